/* Mesh import through the assimp C API, in the caller's process. The file is read into
 * memory and checked (mesh_check.h) before assimp sees it; assimp then runs in a child
 * process (mesh_import_child.c), which reads those bytes through our own file callbacks
 * and writes the mesh into a memory file that this process reads back. Welding is in
 * mesh_import_weld.c, the winding check in mesh_import_defects.c
 * (mesh_import_internal.h). */
#define _GNU_SOURCE /* memfd_create */
#include "scene/mesh_import.h"

#include <ctype.h>
#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <assimp/cimport.h>

#include "core/alloc.h"
#include "core/child.h"
#include "core/file.h"
#include "scene/mesh_check.h"
#include "scene/mesh_import_internal.h"
#include "scene/primitives.h"

/* The whole file (size bytes, as file_check_regular found) into *data. */
static thz_status mesh_import_read(const char *path, const char *name, size_t size, char **data,
                                   thz_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f && errno == ENOMEM)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while opening it", name);
    if (!f)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot open mesh file: %s", name,
                             strerror(errno));
    *data = malloc(size ? size : 1);
    if (!*data) {
        fclose(f);
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while reading %zu bytes", name,
                             size);
    }
    thz_populate(*data, size); /* the kernel's copy into fresh pages faults on each */
    size_t got = fread(*data, 1, size, f);
    int more = fgetc(f) != EOF, failed = ferror(f);
    fclose(f);
    if (failed || got != size || more) {
        free(*data);
        *data = NULL;
        return thz_error_set(err, THZ_ERR_INPUT, "%s: %s while reading the mesh file", name,
                             failed ? "read error" : "the file changed size");
    }
    return THZ_OK;
}

/* Reads n bytes at offset off of fd into p. */
static bool mesh_read_all(int fd, void *p, size_t n, off_t off)
{
    char *c = p;
    while (n > 0) {
        ssize_t r = pread(fd, c, n, off);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            return false;
        c += r;
        n -= (size_t)r;
        off += r;
    }
    return true;
}

/* The parent: the mesh the child wrote into fd. */
static thz_status mesh_import_receive(int fd, const char *name, thz_mesh *mesh, thz_error *err)
{
    uint64_t counts[2];
    struct stat info;
    if (fstat(fd, &info) != 0 || !mesh_read_all(fd, counts, sizeof counts, 0))
        return thz_error_set(err, THZ_ERR_IO, "%s: the imported mesh did not come back", name);
    uint64_t nv = counts[0], nt = counts[1];
    uint64_t bytes = (uint64_t)info.st_size - sizeof counts;
    if (nv > UINT32_MAX || nt > bytes / 12 || nv > bytes / 12 || 12 * (nv + nt) != bytes)
        return thz_error_set(err, THZ_ERR_INTERNAL, "%s: the imported mesh came back garbled",
                             name);
    thz_status st = primitive_mesh_alloc(mesh, (size_t)nv, (size_t)nt, err);
    if (st != THZ_OK)
        return st;
    thz_populate(mesh->positions, 12 * (size_t)nv); /* as mesh_import_read's */
    thz_populate(mesh->indices, 12 * (size_t)nt);
    if (!mesh_read_all(fd, mesh->positions, 12 * (size_t)nv, sizeof counts) ||
        !mesh_read_all(fd, mesh->indices, 12 * (size_t)nt, (off_t)(sizeof counts + 12 * nv))) {
        mesh_fini(mesh);
        return thz_error_set(err, THZ_ERR_IO, "%s: the imported mesh did not come back", name);
    }
    mesh->n_vertices = (size_t)nv;
    mesh->n_triangles = (size_t)nt;
    return THZ_OK;
}

/* The file's format: one thzmap checks (OBJ, PLY, STL), else any other assimp reads by
 * the file name's extension; THZ_ERR_INPUT when assimp reads none such. */
static thz_status mesh_import_format(const char *path, const char *name, mesh_job *job,
                                     thz_error *err)
{
    thz_error checked = {0};
    if (mesh_check_format(path, name, &job->format, &checked) == THZ_OK) {
        snprintf(job->extension, sizeof job->extension, "%s", mesh_format_extension(job->format));
        return THZ_OK;
    }
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    size_t len = dot ? strlen(dot + 1) : 0;
    bool plain = len > 0 && len < sizeof job->extension;
    for (size_t i = 0; plain && i < len; i++)
        plain = isalnum((unsigned char)dot[1 + i]) != 0;
    if (plain && aiIsExtensionSupported(dot) == AI_TRUE) {
        job->format = MESH_FORMAT_OTHER;
        snprintf(job->extension, sizeof job->extension, "%s", dot + 1);
        return THZ_OK;
    }
    return thz_error_set(err, THZ_ERR_INPUT,
                         "%s: unsupported mesh format '%s': thzmap reads %s, and the other "
                         "formats assimp reads, by the file name's extension",
                         name, dot ? dot : "(no extension)", mesh_supported_formats);
}

thz_status mesh_import(const char *path, const char *label, thz_mesh *mesh, thz_error *err)
{
    const char *name = label ? label : path;
    memset(mesh, 0, sizeof *mesh);
    mesh_job job = {.name = name};
    uint64_t size;
    char *data = NULL;
    thz_status st = mesh_import_format(path, name, &job, err);
    mesh_format format = job.format;
    if (st == THZ_OK)
        st = file_check_regular(path, name, MESH_MAX_FILE_BYTES, &size, err);
    if (st == THZ_OK)
        st = mesh_import_read(path, name, (size_t)size, &data, err);
    /* an OBJ saved with a UTF-8 byte-order mark: its first line is a 'v' line all the same
     * (the check, and assimp, dropped it) */
    if (st == THZ_OK && format == MESH_FORMAT_OBJ && size >= 3 &&
        memcmp(data, "\xEF\xBB\xBF", 3) == 0) {
        size -= 3;
        memmove(data, data + 3, (size_t)size);
    }
    if (st == THZ_OK)
        st = mesh_check(data, (size_t)size, format, name, NULL, err);
    if (st != THZ_OK) {
        free(data);
        return st;
    }
    /* assimp frees twice or aborts when an allocation fails (a std::bad_alloc in its
     * post-processing): it runs in a child process (core/child.h), which writes the
     * mesh into a memory file that this process then reads */
    int fd = memfd_create("thzmap-mesh", MFD_CLOEXEC);
    if (fd < 0) {
        free(data);
        return thz_error_set(err, thz_errno_status(errno, THZ_ERR_IO),
                             "%s: cannot import the mesh: memfd_create: %s", name, strerror(errno));
    }
    job.data = data;
    job.size = (size_t)size;
    job.fd = fd;
    char what[256];
    snprintf(what, sizeof what, "importing the mesh %s", name);
    bool crashed = false;
    st = child_run_crash(what, mesh_import_child, &job, 60.0 + 1e-6 * (double)size, &crashed, err);
    free(data);
    if (format == MESH_FORMAT_OTHER && crashed) {
        /* assimp aborted or hung on a file thzmap does not check itself: the file's fault
         * as far as the user can act on it (a child that could not start, or a full disk,
         * stays the system's failure) */
        char why[sizeof err->message];
        snprintf(why, sizeof why, "%s", err->message);
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "%s: assimp cannot import it (%s); check the file, or convert it to "
                           "OBJ, PLY or STL, which thzmap checks before importing",
                           name, why);
    }
    if (st == THZ_OK)
        st = mesh_import_receive(fd, name, mesh, err);
    close(fd);
    return st;
}

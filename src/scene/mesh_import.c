/* Mesh import through the assimp C API, vertex welding and the winding check. The file
 * is read into memory and checked (mesh_check.h) before assimp sees it; assimp then reads
 * those bytes through our own file callbacks, which serve that one file and no other (an
 * OBJ's `mtllib` could otherwise name a FIFO or a device). */
#define _GNU_SOURCE /* memfd_create */
#include "scene/mesh_import.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "core/alloc.h"
#include "core/child.h"
#include "core/file.h"
#include "core/order.h"
#include "scene/mesh_check.h"
#include "scene/primitives.h"

/* Counts the triangles of node and its children (each mesh as often as nodes use it). */
static thz_status mesh_import_count(const struct aiScene *sc, const struct aiNode *node,
                                    size_t depth, size_t *n_vertices, size_t *n_triangles)
{
    if (depth > 1000)
        return THZ_ERR_INPUT;
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        if (node->mMeshes[i] >= sc->mNumMeshes)
            return THZ_ERR_INPUT;
        const struct aiMesh *m = sc->mMeshes[node->mMeshes[i]];
        if (m->mNumVertices && !m->mVertices)
            return THZ_ERR_INPUT;
        *n_vertices += m->mNumVertices;
        for (unsigned f = 0; f < m->mNumFaces; f++) {
            const struct aiFace *face = &m->mFaces[f];
            if (face->mNumIndices != 3)
                continue;
            /* what the checks let through must still index this mesh's vertices */
            for (int k = 0; k < 3; k++)
                if (face->mIndices[k] >= m->mNumVertices)
                    return THZ_ERR_INPUT;
            *n_triangles += 1;
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; c++) {
        thz_status st =
            mesh_import_count(sc, node->mChildren[c], depth + 1, n_vertices, n_triangles);
        if (st != THZ_OK)
            return st;
    }
    return THZ_OK;
}

static void mesh_import_matmul(struct aiMatrix4x4 *out, const struct aiMatrix4x4 *a,
                               const struct aiMatrix4x4 *b)
{
    const float *x = &a->a1, *y = &b->a1;
    float r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r[4 * i + j] = x[4 * i] * y[j] + x[4 * i + 1] * y[4 + j] + x[4 * i + 2] * y[8 + j] +
                           x[4 * i + 3] * y[12 + j];
    memcpy(&out->a1, r, sizeof r);
}

static double mesh_import_det3(const struct aiMatrix4x4 *m)
{
    return (double)m->a1 * ((double)m->b2 * m->c3 - (double)m->b3 * m->c2) -
           (double)m->a2 * ((double)m->b1 * m->c3 - (double)m->b3 * m->c1) +
           (double)m->a3 * ((double)m->b1 * m->c2 - (double)m->b2 * m->c1);
}

/* Appends node's meshes, transformed by parent * node, to out. */
static void mesh_import_append(const struct aiScene *sc, const struct aiNode *node,
                               const struct aiMatrix4x4 *parent, thz_mesh *out)
{
    struct aiMatrix4x4 world;
    mesh_import_matmul(&world, parent, &node->mTransformation);
    bool flip = mesh_import_det3(&world) < 0.0;
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[node->mMeshes[i]];
        size_t base = out->n_vertices;
        for (unsigned v = 0; v < m->mNumVertices; v++) {
            const struct aiVector3D *p = &m->mVertices[v];
            const float *w = &world.a1;
            float *q = &out->positions[3 * (base + v)];
            for (int k = 0; k < 3; k++)
                q[k] = w[4 * k] * p->x + w[4 * k + 1] * p->y + w[4 * k + 2] * p->z + w[4 * k + 3];
        }
        out->n_vertices += m->mNumVertices;
        for (unsigned f = 0; f < m->mNumFaces; f++) {
            const struct aiFace *face = &m->mFaces[f];
            if (face->mNumIndices != 3)
                continue; /* points and lines have no surface */
            uint32_t *t = &out->indices[3 * out->n_triangles];
            t[0] = (uint32_t)(base + face->mIndices[0]);
            t[1] = (uint32_t)(base + face->mIndices[flip ? 2 : 1]);
            t[2] = (uint32_t)(base + face->mIndices[flip ? 1 : 2]);
            out->n_triangles++;
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; c++)
        mesh_import_append(sc, node->mChildren[c], &world, out);
}

/* Orders positions; 0 exactly when the weld merges them (so the sort and the merge
 * agree on what is equal). */
static int mesh_import_position_cmp(const float *x, const float *y)
{
    for (int k = 0; k < 3; k++) {
        if (x[k] < y[k])
            return -1;
        if (x[k] > y[k])
            return 1;
    }
    return 0;
}

/* A finite float's bits as an unsigned number in the float's order (-0 made +0 before). */
static uint64_t mesh_import_float_key(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u & 0x80000000u ? ~u : u | 0x80000000u;
}

/* Puts order[0..n) (vertex indices, increasing) in mesh_import_position_cmp's order, equal
 * positions by index: sorted by z, then y, then x, each a radix sort of (coordinate's key
 * << 32 | place) that keeps the order of equal coordinates. Where qsort's comparisons
 * through pointers took 8-16 % of a 2^24-triangle STL's load. keys: n words of scratch,
 * next: n more places. */
static void mesh_import_position_order(const float *positions, uint32_t *order, uint32_t *next,
                                       uint64_t *keys, size_t n)
{
    for (int k = 2; k >= 0; k--) {
        for (size_t i = 0; i < n; i++)
            keys[i] = mesh_import_float_key(positions[3 * (size_t)order[i] + (size_t)k]) << 32 | i;
        order_sort_u64_threads(keys, n, 1); /* the import's child: no OpenMP team */
        for (size_t i = 0; i < n; i++)
            next[i] = order[keys[i] & 0xffffffffu];
        memcpy(order, next, n * sizeof *order);
    }
}

/* Keeps the vertices that triangles use (those of points and lines have no surface and
 * would widen the bounding box), merging those at the same position, and renumbers
 * them in position order. */
static bool mesh_import_weld(thz_mesh *mesh)
{
    size_t n = mesh->n_vertices;
    uint32_t *order = thz_malloc_array(n, sizeof *order);
    uint32_t *next = thz_malloc_array(n, sizeof *next);
    uint64_t *keys = thz_malloc_array(n, sizeof *keys);
    uint32_t *remap = thz_calloc(n, sizeof *remap);
    float *pos = thz_malloc_array(3 * n + 4, sizeof *pos);
    bool ok = order && next && keys && remap && pos;
    if (!ok)
        goto cleanup;
    /* written whole but for unused vertices: their pages mapped at once */
    thz_populate(order, n * sizeof *order);
    thz_populate(next, n * sizeof *next);
    thz_populate(keys, n * sizeof *keys);
    for (size_t i = 0; i < 3 * mesh->n_triangles; i++)
        remap[mesh->indices[i]] = 1;
    size_t used = 0;
    for (size_t v = 0; v < n; v++) {
        if (!remap[v])
            continue;
        float *p = &mesh->positions[3 * v];
        for (int k = 0; k < 3; k++)
            if (p[k] == 0.0f)
                p[k] = 0.0f; /* -0 becomes +0: one position, one bit pattern */
        order[used++] = (uint32_t)v;
    }
    mesh_import_position_order(mesh->positions, order, next, keys, used);
    size_t unique = 0;
    const float *last = NULL;
    for (size_t i = 0; i < used; i++) {
        const float *p = &mesh->positions[3 * (size_t)order[i]];
        if (!last || mesh_import_position_cmp(p, last) != 0) {
            memcpy(&pos[3 * unique], p, 3 * sizeof(float));
            unique++;
        }
        last = p;
        remap[order[i]] = (uint32_t)(unique - 1);
    }
    memset(&pos[3 * unique], 0, 4 * sizeof *pos);
    for (size_t i = 0; i < 3 * mesh->n_triangles; i++)
        mesh->indices[i] = remap[mesh->indices[i]];
    free(mesh->positions);
    mesh->positions = pos;
    mesh->n_vertices = unique;
    pos = NULL;
cleanup:
    free(order);
    free(next);
    free(keys);
    free(remap);
    free(pos);
    return ok;
}

/* ---- assimp's file callbacks: the checked bytes, and no other file ------------- */

typedef struct mesh_source {
    const char *name; /* what assimp is asked to open: "mesh.<ext>" */
    const char *data;
    size_t size;
} mesh_source;

typedef struct mesh_stream {
    const mesh_source *src;
    size_t pos;
} mesh_stream;

static size_t mesh_io_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
    mesh_stream *s = (mesh_stream *)f->UserData;
    if (size == 0)
        return 0;
    size_t n = (s->src->size - s->pos) / size;
    n = n < count ? n : count;
    memcpy(buf, s->src->data + s->pos, n * size);
    s->pos += n * size;
    return n;
}

static size_t mesh_io_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
    (void)f, (void)buf, (void)size, (void)count;
    return 0;
}

static size_t mesh_io_tell(struct aiFile *f)
{
    return ((mesh_stream *)f->UserData)->pos;
}

static size_t mesh_io_size(struct aiFile *f)
{
    return ((mesh_stream *)f->UserData)->src->size;
}

static enum aiReturn mesh_io_seek(struct aiFile *f, size_t offset, enum aiOrigin origin)
{
    mesh_stream *s = (mesh_stream *)f->UserData;
    size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? s->pos : s->src->size;
    if (offset > s->src->size - base)
        return aiReturn_FAILURE;
    s->pos = base + offset;
    return aiReturn_SUCCESS;
}

static void mesh_io_flush(struct aiFile *f)
{
    (void)f;
}

static struct aiFile *mesh_io_open(struct aiFileIO *io, const char *name, const char *mode)
{
    const mesh_source *src = (const mesh_source *)io->UserData;
    if (strcmp(name, src->name) != 0 || strchr(mode, 'w') || strchr(mode, 'a'))
        return NULL; /* material libraries and the like: not read */
    struct aiFile *f = thz_calloc(1, sizeof *f);
    mesh_stream *s = thz_calloc(1, sizeof *s);
    if (!f || !s) {
        free(f);
        free(s);
        return NULL;
    }
    s->src = src;
    *f = (struct aiFile){mesh_io_read, mesh_io_write, mesh_io_tell, mesh_io_size,
                         mesh_io_seek, mesh_io_flush, (aiUserData)s};
    return f;
}

static void mesh_io_close(struct aiFileIO *io, struct aiFile *f)
{
    (void)io;
    if (f)
        free(f->UserData);
    free(f);
}

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

/* Sanitizer builds reserve terabytes of address space: no RLIMIT_AS there. */
#if defined(__SANITIZE_ADDRESS__)
#define MESH_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define MESH_SANITIZED 1
#endif
#endif
#ifndef MESH_SANITIZED
#define MESH_SANITIZED 0
#endif

/* What the import child needs, and the file (a memfd) it writes the mesh into. */
typedef struct mesh_job {
    const char *name;
    const char *data;
    size_t size;
    mesh_format format;
    char extension[16]; /* what assimp is told the file is */
    int fd;
} mesh_job;

/* text into out with every `from` (the name assimp was given) replaced by `to` (the
 * user's), cut to fit. */
static void mesh_rename_in(const char *text, const char *from, const char *to, char *out,
                           size_t size)
{
    size_t n = 0, from_len = strlen(from), to_len = strlen(to);
    while (*text && n + 1 < size) {
        if (strncmp(text, from, from_len) == 0) {
            size_t k = to_len < size - 1 - n ? to_len : size - 1 - n;
            memcpy(out + n, to, k);
            n += k;
            text += from_len;
        } else {
            out[n++] = *text++;
        }
    }
    out[n] = '\0';
}

/* Imports job's bytes with assimp into mesh (triangulated, welded). In the child. */
static thz_status mesh_import_assimp(const mesh_job *job, thz_mesh *mesh, thz_error *err)
{
    const char *name = job->name;
    thz_status st = THZ_OK;
    memset(mesh, 0, sizeof *mesh);
    char fake_name[32];
    snprintf(fake_name, sizeof fake_name, "mesh.%s", job->extension);
    mesh_source src = {fake_name, job->data, job->size};
    struct aiFileIO io = {mesh_io_open, mesh_io_close, (aiUserData)&src};
    /* assimp reports an allocation failure (a std::bad_alloc it catches) as a reading
     * error; the C library's ENOMEM in errno tells it apart from a bad file */
    errno = 0;
    const struct aiScene *sc = aiImportFileEx(fake_name, aiProcess_Triangulate, &io);
    if (!sc && errno == ENOMEM)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while importing the mesh",
                             name);
    if (!sc) {
        const char *why = aiGetErrorString();
        char said[512];
        mesh_rename_in(why && why[0] ? why : "unknown format", fake_name, name, said, sizeof said);
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot read as a mesh: %s", name, said);
    }
    size_t nv = 0, nt = 0;
    if (!sc->mRootNode || mesh_import_count(sc, sc->mRootNode, 0, &nv, &nt) != THZ_OK) {
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "%s: the importer's result is malformed (its node tree, or a face "
                           "index beyond its vertices)",
                           name);
        goto cleanup;
    }
    if (nt == 0) {
        st = thz_error_set(err, THZ_ERR_INPUT, "%s: the mesh has no triangles", name);
        goto cleanup;
    }
    if (nv > UINT32_MAX) {
        st = thz_error_set(err, THZ_ERR_INPUT, "%s: more than %u vertices", name, UINT32_MAX);
        goto cleanup;
    }
    if (nt > MESH_MAX_TRIANGLES) { /* the checked formats are refused before this */
        st = thz_error_set(err, THZ_ERR_INPUT, "%s: %zu triangles, more than the limit of %u", name,
                           nt, MESH_MAX_TRIANGLES);
        goto cleanup;
    }
    st = primitive_mesh_alloc(mesh, nv, nt, err);
    if (st != THZ_OK)
        goto cleanup;
    mesh->n_vertices = 0;
    mesh->n_triangles = 0;
    struct aiMatrix4x4 identity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    mesh_import_append(sc, sc->mRootNode, &identity, mesh);
    for (size_t i = 0; i < 3 * mesh->n_vertices; i++) {
        if (!isfinite(mesh->positions[i])) {
            st = thz_error_set(err, THZ_ERR_INPUT,
                               "%s: vertex %zu has a coordinate that is not a finite number", name,
                               i / 3 + 1);
            goto cleanup;
        }
    }
    if (!mesh_import_weld(mesh)) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", name);
        goto cleanup;
    }
cleanup:
    aiReleaseImport(sc);
    if (st != THZ_OK)
        mesh_fini(mesh);
    return st;
}

/* Writes all n bytes of p to fd. */
static bool mesh_write_all(int fd, const void *p, size_t n)
{
    const char *c = p;
    while (n > 0) {
        ssize_t w = write(fd, c, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return false;
        c += w;
        n -= (size_t)w;
    }
    return true;
}

/* The child: imports, then writes the vertex and triangle counts (uint64 each), the
 * positions (3 floats per vertex) and the indices (3 per triangle) into job->fd. */
static thz_status mesh_import_child(void *arg, thz_error *err)
{
    const mesh_job *job = arg;
    /* what assimp prints (the assertion it fails before it aborts) is not the library's
     * to say: the parent reports the failure (a sanitizer's report stays on stderr) */
    int quiet = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (quiet >= 0) {
        dup2(quiet, STDOUT_FILENO);
        if (!MESH_SANITIZED)
            dup2(quiet, STDERR_FILENO);
        close(quiet);
    }
#if !MESH_SANITIZED
    /* a format only assimp checks: a header that asks for more memory than the machine
     * has fails here, in the child, not in the machine's other processes. The limit is on
     * top of the address space the child inherits (a Python or `thzmap serve` process may
     * hold large results while it loads a scene). */
    uint64_t have = thz_physical_memory_bytes();
    unsigned long long pages = 0;
    FILE *statm = fopen("/proc/self/statm", "r");
    if (statm) {
        if (fscanf(statm, "%llu", &pages) != 1)
            pages = 0;
        fclose(statm);
    }
    long page = sysconf(_SC_PAGESIZE);
    if (job->format == MESH_FORMAT_OTHER && have > 0 && statm && page > 0) {
        rlim_t limit = (rlim_t)(pages * (unsigned long long)page + have / 2);
        struct rlimit rl = {limit, limit};
        setrlimit(RLIMIT_AS, &rl);
    }
#endif
    thz_mesh mesh;
    thz_status st = mesh_import_assimp(job, &mesh, err);
    if (st != THZ_OK)
        return st;
    uint64_t counts[2] = {mesh.n_vertices, mesh.n_triangles};
    if (!mesh_write_all(job->fd, counts, sizeof counts) ||
        !mesh_write_all(job->fd, mesh.positions, 3 * mesh.n_vertices * sizeof *mesh.positions) ||
        !mesh_write_all(job->fd, mesh.indices, 3 * mesh.n_triangles * sizeof *mesh.indices))
        st = thz_error_set(err, thz_errno_status(errno, THZ_ERR_IO),
                           "%s: cannot pass the imported mesh on: %s", job->name, strerror(errno));
    mesh_fini(&mesh);
    return st;
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

/* A triangle by its corners in increasing order, and its index. */
typedef struct mesh_corners {
    uint32_t v[3];
    uint32_t t;
} mesh_corners;

static int mesh_corners_cmp(const void *a, const void *b)
{
    const mesh_corners *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->v[k] != y->v[k])
            return x->v[k] < y->v[k] ? -1 : 1;
    return x->t < y->t ? -1 : x->t > y->t;
}

/* Twice the area of the triangle with corners v (its cross product's length). */
static double mesh_triangle_area2(const thz_mesh *mesh, const uint32_t *v)
{
    const float *p = mesh->positions;
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = (double)p[3 * v[1] + k] - p[3 * v[0] + k];
        e2[k] = (double)p[3 * v[2] + k] - p[3 * v[0] + k];
    }
    double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

bool mesh_import_defects(const thz_mesh *mesh, mesh_defects *out)
{
    *out = (mesh_defects){0};
    size_t nt = mesh->n_triangles;
    mesh_corners *tri = thz_malloc_array(nt ? nt : 1, sizeof *tri);
    bool *repeat = thz_calloc(nt ? nt : 1, sizeof *repeat); /* left out of the edges */
    uint64_t *edges = thz_malloc_array(3 * nt + 1, sizeof *edges);
    if (!tri || !repeat || !edges) {
        free(tri);
        free(repeat);
        free(edges);
        return false;
    }
    thz_populate(tri, nt * sizeof *tri); /* written whole, edges nearly: pages at once */
    thz_populate(edges, 3 * nt * sizeof *edges);
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *v = &mesh->indices[3 * t];
        uint32_t a = v[0], b = v[1], c = v[2], x;
        if (a > b)
            x = a, a = b, b = x;
        if (b > c)
            x = b, b = c, c = x;
        if (a > b)
            x = a, a = b, b = x;
        tri[t] = (mesh_corners){{a, b, c}, (uint32_t)t};
        if (a == b || b == c || !(mesh_triangle_area2(mesh, v) > 0.0)) {
            out->degenerate++;
            repeat[t] = true; /* nor has it a side to wind */
        }
    }
    /* the same three corners, whichever way round: each after the first is a repeat */
    qsort(tri, nt, sizeof *tri, mesh_corners_cmp);
    for (size_t i = 1; i < nt; i++)
        if (!memcmp(tri[i].v, tri[i - 1].v, sizeof tri[i].v) && !repeat[tri[i].t]) {
            repeat[tri[i].t] = true;
            out->repeated++;
        }
    size_t m = 0;
    for (size_t t = 0; t < nt; t++) {
        if (repeat[t])
            continue;
        const uint32_t *v = &mesh->indices[3 * t];
        for (int k = 0; k < 3; k++) {
            uint32_t a = v[k], b = v[(k + 1) % 3];
            if (a != b)
                edges[m++] = ((uint64_t)a << 32) | b;
        }
    }
    order_sort_u64(edges, m);
    for (size_t i = 1; i < m; i++)
        if (edges[i] == edges[i - 1] && (i < 2 || edges[i - 1] != edges[i - 2]))
            out->winding_conflicts++;
    free(tri);
    free(repeat);
    free(edges);
    return true;
}

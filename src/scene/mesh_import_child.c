/* The mesh import's child process (mesh_import.c starts it): assimp reads the checked
 * bytes through our own file callbacks, which serve that one file and no other (an OBJ's
 * `mtllib` could otherwise name a FIFO or a device); the node tree is baked into one
 * triangle mesh (node transforms applied, winding kept), welded (mesh_import_weld.c) and
 * written into the memory file the parent reads back (mesh_import_internal.h). */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "core/alloc.h"
#include "core/file.h"
#include "scene/mesh_check.h"
#include "scene/mesh_import_internal.h"
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

thz_status mesh_import_child(void *arg, thz_error *err)
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

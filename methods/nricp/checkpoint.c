/* nricp checkpoint: the consecutive vertex maps, so a resumed run does not
 * register every frame pair again. The normals are recomputed on load (cheap
 * and exactly reproducible from the sequence).
 *
 * Binary, host byte order (a cache for the machine that wrote it):
 *     char     magic[8]      "TCBNRICP"
 *     int32    version       1
 *     int32    strategy, rounds, smooth, smooth_last, k
 *     int32    n_frames, n_verts
 *     uint64   FNV-1a hash of the sequence's vertex coordinates (and block starts)
 *     int32    maps[2][n_frames − 1][n_verts]   (propagate_simple/bijective only)
 * Load refuses a file written for another strategy, other parameters or
 * another sequence, any map entry outside the frame and, for
 * propagate_bijective, a map that is not a permutation. */
#include <stdlib.h>
#include <string.h>

#include "methods/nricp/nricp_internal.h"
#include "tcb/fsutil.h"

#define MAGIC "TCBNRICP"
#define VERSION 1
#define N_FIELDS 8 /* the int32 fields after the magic */
#define HEADER_BYTES (8 + N_FIELDS * 4 + 8)

static uint64_t fnv1a(uint64_t h, const void *data, size_t len)
{
    const unsigned char *b = data;
    for (size_t k = 0; k < len; k++) h = (h ^ b[k]) * 1099511628211ull;
    return h;
}

/* The blocks decide which maps are registered (maps.c): they are hashed
 * too, after the vertices, so a sequence without blocks keeps its hash. */
uint64_t nricp_sequence_hash(const tcb_sequence *seq)
{
    size_t len = (size_t)seq->n_frames * seq->n_verts * 3 * sizeof(float);
    uint64_t h = fnv1a(1469598103934665603ull, seq->verts, len);
    for (int k = 0; k < seq->n_blocks; k++) h = fnv1a(h, &seq->blocks[k].start, sizeof seq->blocks[k].start);
    return h;
}

static void header_fields(const nricp_method *m, int32_t f[N_FIELDS])
{
    const nricp_params *p = &m->params;
    int32_t v[N_FIELDS] = {VERSION, (int32_t)m->strategy, p->rounds, p->smooth, p->smooth_last, p->k,
                           m->n_frames, m->n_verts};
    memcpy(f, v, sizeof v);
}

static size_t file_size(const nricp_method *m)
{
    return HEADER_BYTES + (nricp_uses_maps(m->strategy) ? nricp_maps_len(m) * sizeof(int32_t) : 0);
}

int nricp_save(void *self, const char *path, tcb_error *err)
{
    const nricp_method *m = self;
    if (!m->normals) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: nricp model saved before fit", path);
    size_t len = file_size(m);
    unsigned char *buf = malloc(len);
    if (!buf) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    int32_t f[N_FIELDS];
    header_fields(m, f);
    memcpy(buf, MAGIC, 8);
    memcpy(buf + 8, f, sizeof f);
    memcpy(buf + 8 + sizeof f, &m->seq_hash, 8);
    if (nricp_uses_maps(m->strategy)) memcpy(buf + HEADER_BYTES, m->maps, len - HEADER_BYTES);
    int rc = tcb_write_file_atomic(path, buf, len, err);
    free(buf);
    return rc;
}

static int check_header(const nricp_method *m, const unsigned char *buf, size_t len, const char *path,
                        tcb_error *err)
{
    if (len < HEADER_BYTES || memcmp(buf, MAGIC, 8) != 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: not an nricp checkpoint", path);
    int32_t got[N_FIELDS], want[N_FIELDS];
    uint64_t hash;
    memcpy(got, buf + 8, sizeof got);
    memcpy(&hash, buf + 8 + sizeof got, 8);
    header_fields(m, want);
    static const char *const names[N_FIELDS] = {"format version", "strategy", "rounds", "smooth",
                                                "smooth_last", "k", "frame count", "vertex count"};
    for (int k = 0; k < N_FIELDS; k++)
        if (got[k] != want[k])
            return tcb_fail(err, TCB_ERR_INPUT, "%s: written with %s %d, this run has %d", path, names[k],
                            (int)got[k], (int)want[k]);
    if (hash != m->seq_hash)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: written for another sequence (vertex hash differs)", path);
    if (len != file_size(m))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %zu bytes, expected %zu (truncated or padded)", path, len,
                        file_size(m));
    return TCB_OK;
}

/* Every entry a vertex of the frame; for propagate_bijective every row a
 * permutation. */
static int check_maps(const nricp_method *m, const char *path, tcb_error *err)
{
    int nv = m->n_verts, rows = 2 * (m->n_frames - 1), rc = TCB_OK;
    unsigned char *seen = malloc((size_t)nv);
    if (!seen) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    for (int r = 0; r < rows && !rc; r++) {
        const int32_t *row = m->maps + (size_t)r * nv;
        memset(seen, 0, (size_t)nv);
        for (int v = 0; v < nv && !rc; v++) {
            if (row[v] < 0 || row[v] >= nv)
                rc = tcb_fail(err, TCB_ERR_INPUT, "%s: map %d, vertex %d: index %d outside 0..%d", path, r, v,
                              (int)row[v], nv - 1);
            else if (m->strategy == NRICP_BIJECTIVE && seen[row[v]]++)
                rc = tcb_fail(err, TCB_ERR_INPUT, "%s: map %d is not a permutation (vertex %d hit twice)",
                              path, r, (int)row[v]);
        }
    }
    free(seen);
    return rc;
}

int nricp_load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err)
{
    nricp_method *m = self;
    char *buf = NULL;
    size_t len = 0;
    int rc = tcb_read_file(path, &buf, &len, err);
    if (!rc) rc = nricp_prepare(m, seq, err);
    if (!rc) rc = check_header(m, (const unsigned char *)buf, len, path, err);
    if (!rc && nricp_uses_maps(m->strategy)) {
        free(m->maps);
        m->maps = malloc(nricp_maps_len(m) * sizeof *m->maps);
        if (!m->maps) rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
        else memcpy(m->maps, buf + HEADER_BYTES, nricp_maps_len(m) * sizeof *m->maps);
        if (!rc) rc = check_maps(m, path, err);
    }
    free(buf);
    return rc;
}

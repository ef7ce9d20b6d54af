/* nricp checkpoint: the consecutive vertex maps, so a resumed run does not
 * register every frame pair again. The same file holds the state of an
 * unfinished fit (maps.c writes it to the cell's work directory when the
 * run is asked to stop, and every minute): a done flag per map says which
 * rows are computed. The normals are recomputed on load (cheap and exactly
 * reproducible from the sequence).
 *
 * Binary, host byte order (a cache for the machine that wrote it):
 *     char     magic[8]      "TCBNRICP"
 *     int32    version       3
 *     int32    strategy, rounds, smooth, smooth_last, k
 *     int32    n_frames, n_verts
 *     uint64   FNV-1a hash of the sequence's vertex coordinates (and block starts)
 *     float64  seconds the unfinished fit had cost (0 in a finished model,
 *              whose fit time its cell records)
 *     uint8    done[2][n_frames − 1]          (propagate_simple/bijective only)
 *     int32    maps[2][n_frames − 1][n_verts] (the same; rows not done are 0)
 *     uint64   FNV-1a of every byte before it
 * Reading refuses a file written for another strategy, other parameters or
 * another sequence, one whose checksum does not match (a flipped bit can
 * leave a valid vertex id), a done flag other than 0 or 1, any map entry
 * outside the frame and, for propagate_bijective, a map that is not a
 * permutation. Versions 1 (no seconds, no flags) and 2 (no checksum) are
 * refused by their version: the run fits again. */
#include <stdlib.h>
#include <string.h>

#include "methods/nricp/nricp_internal.h"
#include "tcb/fsutil.h"
#include "tcb/hash.h"

#define MAGIC "TCBNRICP"
#define VERSION 3
#define N_FIELDS 8 /* the int32 fields after the magic */
#define HEADER_BYTES (8 + N_FIELDS * 4 + 8 + 8)

/* The blocks decide which maps are registered (maps.c): they are hashed
 * too, after the vertices, so a sequence without blocks keeps its hash. */
uint64_t nricp_sequence_hash(const tcb_sequence *seq)
{
    size_t len = (size_t)seq->n_frames * seq->n_verts * 3 * sizeof(float);
    uint64_t h = tcb_fnv1a64(TCB_FNV1A64_OFFSET, seq->verts, len);
    for (int k = 0; k < seq->n_blocks; k++) h = tcb_fnv1a64(h, &seq->blocks[k].start, sizeof seq->blocks[k].start);
    return h;
}

static void header_fields(const nricp_method *m, int32_t f[N_FIELDS])
{
    const nricp_params *p = &m->params;
    int32_t v[N_FIELDS] = {VERSION, (int32_t)m->strategy, p->rounds, p->smooth, p->smooth_last, p->k,
                           m->n_frames, m->n_verts};
    memcpy(f, v, sizeof v);
}

static size_t map_rows(const nricp_method *m)
{
    return nricp_uses_maps(m->strategy) ? 2 * (size_t)(m->n_frames - 1) : 0;
}

static size_t file_size(const nricp_method *m)
{
    return HEADER_BYTES + map_rows(m) * (1 + (size_t)m->n_verts * sizeof(int32_t)) + sizeof(uint64_t);
}

/* Only the rows marked done are read: the others may be in the middle of
 * being written by another thread of the fit. */
int nricp_write_state(const nricp_method *m, const unsigned char *done, double fit_s, const char *path,
                      tcb_error *err)
{
    if (!m->normals) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: nricp model saved before fit", path);
    size_t len = file_size(m), rows = map_rows(m), row_bytes = (size_t)m->n_verts * sizeof(int32_t);
    unsigned char *buf = calloc(len, 1);
    if (!buf) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    int32_t f[N_FIELDS];
    header_fields(m, f);
    memcpy(buf, MAGIC, 8);
    memcpy(buf + 8, f, sizeof f);
    memcpy(buf + 8 + sizeof f, &m->seq_hash, 8);
    memcpy(buf + 8 + sizeof f + 8, &fit_s, 8);
    unsigned char *flags = buf + HEADER_BYTES, *maps = flags + rows;
    for (size_t r = 0; r < rows; r++) {
        flags[r] = done ? done[r] : 1;
        if (flags[r]) memcpy(maps + r * row_bytes, m->maps + r * (size_t)m->n_verts, row_bytes);
    }
    uint64_t sum = tcb_fnv1a64(TCB_FNV1A64_OFFSET, buf, len - sizeof sum);
    memcpy(buf + len - sizeof sum, &sum, sizeof sum);
    int rc = tcb_write_file_atomic(path, buf, len, err);
    free(buf);
    return rc;
}

int nricp_save(void *self, const char *path, tcb_error *err)
{
    return nricp_write_state(self, NULL, 0, path, err);
}

static int check_header(const nricp_method *m, const unsigned char *buf, size_t len, const char *path,
                        tcb_error *err)
{
    if (len < 8 + sizeof(int32_t) || memcmp(buf, MAGIC, 8) != 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: not an nricp checkpoint", path);
    int32_t got[N_FIELDS] = {0}, want[N_FIELDS];
    memcpy(got, buf + 8, len < HEADER_BYTES ? sizeof(int32_t) : sizeof got);
    header_fields(m, want);
    static const char *const names[N_FIELDS] = {"format version", "strategy", "rounds", "smooth",
                                                "smooth_last", "k", "frame count", "vertex count"};
    if (got[0] == want[0] && len < HEADER_BYTES)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %zu bytes, shorter than the header (truncated)", path, len);
    for (int k = 0; k < N_FIELDS; k++)
        if (got[k] != want[k])
            return tcb_fail(err, TCB_ERR_INPUT, "%s: written with %s %d, this run has %d", path, names[k],
                            (int)got[k], (int)want[k]);
    uint64_t hash;
    memcpy(&hash, buf + 8 + sizeof got, 8);
    if (hash != m->seq_hash)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: written for another sequence (vertex hash differs)", path);
    if (len != file_size(m))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %zu bytes, expected %zu (truncated or padded)", path, len,
                        file_size(m));
    uint64_t sum;
    memcpy(&sum, buf + len - sizeof sum, sizeof sum);
    if (tcb_fnv1a64(TCB_FNV1A64_OFFSET, buf, len - sizeof sum) != sum)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: checksum mismatch (corrupted file)", path);
    return TCB_OK;
}

/* Every entry of a done row a vertex of the frame; for propagate_bijective
 * every such row a permutation. */
static int check_maps(const nricp_method *m, const unsigned char *done, const char *path, tcb_error *err)
{
    int nv = m->n_verts, rows = (int)map_rows(m), rc = TCB_OK;
    unsigned char *seen = malloc((size_t)nv);
    if (!seen) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    for (int r = 0; r < rows && !rc; r++) {
        if (done[r] > 1) rc = tcb_fail(err, TCB_ERR_INPUT, "%s: map %d: done flag %d (not 0 or 1)", path, r, done[r]);
        if (rc || !done[r]) continue;
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

int nricp_read_state(nricp_method *m, unsigned char *done, double *fit_s, const char *path, tcb_error *err)
{
    char *buf = NULL;
    size_t len = 0, rows = map_rows(m);
    int rc = tcb_read_file(path, &buf, &len, err);
    if (!rc) rc = check_header(m, (const unsigned char *)buf, len, path, err);
    if (!rc) memcpy(fit_s, buf + HEADER_BYTES - 8, 8);
    if (!rc && rows) {
        free(m->maps);
        m->maps = malloc(nricp_maps_len(m) * sizeof *m->maps);
        if (!m->maps) rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
        if (!rc) {
            memcpy(done, buf + HEADER_BYTES, rows);
            memcpy(m->maps, buf + HEADER_BYTES + rows, nricp_maps_len(m) * sizeof *m->maps);
            rc = check_maps(m, done, path, err);
        }
    }
    free(buf);
    return rc;
}

int nricp_load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err)
{
    nricp_method *m = self;
    int rc = nricp_prepare(m, seq, err);
    size_t rows = map_rows(m);
    unsigned char *done = malloc(rows + 1);
    double fit_s;
    if (!rc && !done) rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    if (!rc) rc = nricp_read_state(m, done, &fit_s, path, err);
    size_t finished = 0;
    for (size_t r = 0; !rc && r < rows; r++) finished += done[r];
    if (!rc && finished < rows)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: an unfinished fit (%zu of %zu maps), not a fitted model", path,
                      finished, rows);
    free(done);
    return rc;
}

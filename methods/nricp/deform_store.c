/* A finished propagate_deform chain in the cell's work directory, so that
 * an evaluation stopped or killed after hours keeps every chain it
 * finished (deform.c). One file per (source, direction), written
 * atomically when the chain ends; kept with the cell's model, since an
 * evaluation killed later needs them again, and removed with it by --force.
 *
 * Binary, host byte order (a cache for the machine that wrote it):
 *     char     magic[8]      "TCBNRDEF"
 *     int32    version       1
 *     int32    rounds, smooth, smooth_last, k
 *     int32    n_frames, n_verts
 *     int32    source, step (+1 or −1), n_targets
 *     uint64   nricp_sequence_hash of the sequence
 *     int32    targets[n_targets]                 frames, nearest first
 *     float32  outs[n_targets][n_verts][3]        X at each target
 *     uint64   FNV-1a of every byte before it
 * Reading refuses a file written with other parameters, for another
 * sequence or chain, one whose checksum does not match, targets outside
 * the chain's direction or not nearest first, non-finite points, and a
 * file lacking a target the chain needs (written for other pairs). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/nricp/nricp_internal.h"
#include "tcb/fsutil.h"
#include "tcb/geometry.h"
#include "tcb/hash.h"

#define MAGIC "TCBNRDEF"
#define VERSION 1
#define N_FIELDS 10 /* the int32 fields after the magic */
#define HEADER_BYTES (8 + N_FIELDS * 4 + 8)

int nricp_chain_path(const char *work_dir, const nricp_chain *c, char *path, size_t size, tcb_error *err)
{
    return tcb_path_join(path, size, err, "%s/nricp_deform_%d_%s.bin", work_dir, c->source,
                         c->step > 0 ? "forward" : "backward");
}

static void header_fields(const nricp_method *m, const nricp_chain *c, int32_t f[N_FIELDS])
{
    const nricp_params *p = &m->params;
    int32_t v[N_FIELDS] = {VERSION,     p->rounds,  p->smooth, p->smooth_last, p->k,
                           m->n_frames, m->n_verts, c->source, c->step,        c->n_targets};
    memcpy(f, v, sizeof v);
}

static size_t frame_bytes(const nricp_method *m) { return (size_t)m->n_verts * 3 * sizeof(float); }

static size_t file_size(const nricp_method *m, int n_targets)
{
    return HEADER_BYTES + (size_t)n_targets * (sizeof(int32_t) + frame_bytes(m)) + sizeof(uint64_t);
}

int nricp_chain_write(const nricp_method *m, const nricp_chain *c, const char *path, tcb_error *err)
{
    size_t len = file_size(m, c->n_targets);
    unsigned char *buf = malloc(len);
    if (!buf) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    int32_t f[N_FIELDS];
    header_fields(m, c, f);
    unsigned char *at = buf;
    memcpy(at, MAGIC, 8), at += 8;
    memcpy(at, f, sizeof f), at += sizeof f;
    memcpy(at, &m->seq_hash, 8), at += 8;
    for (int t = 0; t < c->n_targets; t++, at += sizeof(int32_t)) {
        int32_t target = c->targets[t];
        memcpy(at, &target, sizeof target);
    }
    memcpy(at, c->outs, (size_t)c->n_targets * frame_bytes(m)), at += (size_t)c->n_targets * frame_bytes(m);
    uint64_t sum = tcb_fnv1a64(TCB_FNV1A64_OFFSET, buf, len - sizeof sum);
    memcpy(at, &sum, sizeof sum);
    int rc = tcb_write_file_atomic(path, buf, len, err);
    free(buf);
    return rc;
}

/* The header against the chain it should hold; *n_targets gets the file's
 * target count (n_targets, the field the chain cannot predict, is the
 * last one compared and is not). */
static int check_header(const nricp_method *m, const nricp_chain *c, const unsigned char *buf, size_t len,
                        const char *path, int *n_targets, tcb_error *err)
{
    static const char *const names[N_FIELDS - 1] = {"format version", "rounds", "smooth", "smooth_last", "k",
                                                    "frame count", "vertex count", "source frame", "direction"};
    if (len < 8 || memcmp(buf, MAGIC, 8) != 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: not an nricp deform chain", path);
    if (len < HEADER_BYTES + sizeof(uint64_t))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %zu bytes, shorter than the header (truncated)", path, len);
    int32_t got[N_FIELDS], want[N_FIELDS];
    memcpy(got, buf + 8, sizeof got);
    header_fields(m, c, want);
    for (int k = 0; k < N_FIELDS - 1; k++)
        if (got[k] != want[k])
            return tcb_fail(err, TCB_ERR_INPUT, "%s: written with %s %d, this chain has %d", path, names[k],
                            (int)got[k], (int)want[k]);
    uint64_t hash, sum;
    memcpy(&hash, buf + 8 + sizeof got, 8);
    if (hash != m->seq_hash)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: written for another sequence (vertex hash differs)", path);
    int n = got[N_FIELDS - 1];
    if (n < 1 || n > m->n_frames || len != file_size(m, n))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %zu bytes for %d targets (truncated or padded)", path, len, (int)n);
    memcpy(&sum, buf + len - sizeof sum, sizeof sum);
    if (tcb_fnv1a64(TCB_FNV1A64_OFFSET, buf, len - sizeof sum) != sum)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: checksum mismatch (corrupted file)", path);
    *n_targets = n;
    return TCB_OK;
}

/* Targets strictly farther along the chain's direction, inside the frames. */
static int check_targets(const nricp_method *m, const nricp_chain *c, const int32_t *targets, int n,
                         const char *path, tcb_error *err)
{
    for (int t = 0, last = c->source; t < n; last = targets[t++]) {
        int d = (targets[t] - last) * c->step;
        if (targets[t] < 0 || targets[t] >= m->n_frames || d <= 0)
            return tcb_fail(err, TCB_ERR_INPUT, "%s: target %d is frame %d, not beyond frame %d going %s", path, t,
                            (int)targets[t], last, c->step > 0 ? "forward" : "backward");
    }
    return TCB_OK;
}

int nricp_chain_read(const nricp_method *m, nricp_chain *c, const char *path, tcb_error *err)
{
    char *raw = NULL;
    size_t len = 0;
    int n = 0, rc = tcb_read_file(path, &raw, &len, err);
    const unsigned char *buf = (const unsigned char *)raw;
    if (!rc) rc = check_header(m, c, buf, len, path, &n, err);
    int32_t *targets = rc ? NULL : malloc((size_t)n * sizeof *targets);
    if (!rc && !targets) rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    if (!rc) memcpy(targets, buf + HEADER_BYTES, (size_t)n * sizeof *targets);
    if (!rc) rc = check_targets(m, c, targets, n, path, err);
    const unsigned char *outs = buf + HEADER_BYTES + (size_t)n * sizeof *targets;
    if (!rc && !tcb_all_finite((const float *)outs, (size_t)n * m->n_verts * 3))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: a deformed point is not finite", path);
    /* Both lists go nearest first: one merge finds every target the chain needs. */
    for (int t = 0, s = 0; !rc && t < c->n_targets; t++) {
        while (s < n && (targets[s] - c->targets[t]) * c->step < 0) s++;
        if (s == n || targets[s] != c->targets[t])
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s: has no deformed cloud at frame %d (written for other pairs)",
                          path, c->targets[t]);
        else memcpy(c->outs + (size_t)t * m->n_verts * 3, outs + (size_t)s * frame_bytes(m), frame_bytes(m));
    }
    free(targets);
    free(raw);
    return rc;
}

/* The nricp method's state, shared by its table (nricp.c), its setup
 * (prepare.c), the consecutive maps (maps.c), the checkpoint
 * (checkpoint.c) and the deform chains and random batches. */
#ifndef TCB_NRICP_INTERNAL_H
#define TCB_NRICP_INTERNAL_H

#include <stdint.h>

#include "methods/nricp/register.h"
#include "tcb/method.h"
#include "tcb/rng.h"

/* Reference-protocol §6.3; TCSR's names in parentheses in nricp.c. */
typedef enum nricp_strategy {
    NRICP_RANDOM = 0,
    NRICP_SIMPLE = 1,
    NRICP_BIJECTIVE = 2,
    NRICP_DEFORM = 3
} nricp_strategy;

extern const char *const nricp_strategy_names[]; /* NULL-terminated, indexed by nricp_strategy */

/* A propagate_deform chain (deform.c): X from frame `source`, one step of
 * `step` (±1) at a time, kept at each target frame, nearest first. */
typedef struct nricp_chain {
    int source, step, n_targets;
    int *targets;  /* [n_targets] */
    float *outs;   /* [n_targets][n_verts][3] */
} nricp_chain;

typedef struct nricp_chains {
    int n;
    nricp_chain *c;
} nricp_chains;

/* random: the pairs prepare_pairs announced and a batch of their
 * registrations, computed ahead (random_ahead.c). */
typedef struct nricp_ahead {
    int n, next;        /* announced pairs; the index of the next expected */
    int *pairs;         /* [n][2] frames i, j */
    int threads, cap;   /* the cell's threads; pairs per batch */
    int first, count;   /* the batch in outs: pairs first .. first + count − 1 */
    float *outs;        /* [cap][n_verts][3] */
} nricp_ahead;

typedef struct nricp_method {
    nricp_strategy strategy;
    nricp_params params;
    int n_frames, n_verts; /* of the fitted sequence; 0 before fit/load */
    float *normals;        /* [n_frames][n_verts][3] area-weighted vertex normals */
    /* Consecutive vertex maps, propagate_simple/bijective only (else NULL):
     * [2][n_frames − 1][n_verts]; block 0 row k maps frame k → k+1, block 1
     * row k maps frame k+1 → k. */
    int32_t *maps;
    uint64_t seq_hash; /* nricp_sequence_hash of the fitted sequence */
    /* propagate_deform: the chains of the pairs prepare_pairs announced
     * (n = 0 before, and for the other strategies). */
    nricp_chains chains;
    nricp_ahead ahead; /* random only (else empty) */
    tcb_rng unit_pairs; /* the frames of run_unit's registrations (nricp.c) */
} nricp_method;

static inline int nricp_uses_maps(nricp_strategy s)
{
    return s == NRICP_SIMPLE || s == NRICP_BIJECTIVE;
}

static inline size_t nricp_maps_len(const nricp_method *m)
{
    return 2 * (size_t)(m->n_frames - 1) * (size_t)m->n_verts;
}

/* Frame f's vertex normals. */
static inline const float *nricp_normals_of(const nricp_method *m, int f)
{
    return m->normals + (size_t)f * m->n_verts * 3;
}

/* The row of maps mapping frame a to the adjacent frame b = a ± 1, and its offset. */
static inline size_t nricp_map_row(const nricp_method *m, int a, int b)
{
    return b > a ? (size_t)a : (size_t)(m->n_frames - 1) + (size_t)b;
}

static inline size_t nricp_map_at(const nricp_method *m, int a, int b)
{
    return nricp_map_row(m, a, b) * (size_t)m->n_verts;
}

/* prepare.c: sizes, sequence hash and vertex normals of seq (fit and
 * load both start here); drops the chains and batches of the model it
 * replaces. */
int nricp_prepare(nricp_method *m, const tcb_sequence *seq, tcb_error *err);

/* maps.c: compute every consecutive map (OpenMP over the 2(F−1)
 * registrations, progress through ctx->reporter), and compose them. A stop
 * request (ctx->interrupted) saves the maps done so far in ctx->work_dir
 * and returns TCB_ERR_INTERRUPTED; the next fit there continues them. */
int nricp_fit_maps(nricp_method *m, const tcb_sequence *seq, const tcb_fit_ctx *ctx,
                   tcb_error *err);
void nricp_compose(const nricp_method *m, int i, int j, int32_t *idx);
/* The exact linear assignment of n moved points to n target points on
 * squared distances (propagate_bijective's matching): map [n]. */
int nricp_assign(const float *moved, const float *target, int n, int32_t *map, tcb_error *err);

/* deform.c: the chains of the n pairs (pairs[2p] → pairs[2p + 1]) into
 * m->chains, in parallel (ctx->n_threads), each saved in ctx->work_dir
 * when it ends and reused from there; a stop request ends it with
 * TCB_ERR_INTERRUPTED. transfer takes an announced pair's X from there and
 * runs the chain of any other. */
int nricp_deform_pairs(nricp_method *m, const tcb_sequence *seq, const int *pairs, int n,
                       const tcb_fit_ctx *ctx, tcb_error *err);
int nricp_deform_transfer(const nricp_method *m, const tcb_sequence *seq, int i, int j, const float *src,
                          float *out, tcb_error *err);
void nricp_chains_free(nricp_chains *cs);

/* random_ahead.c: announce resets the batches to the n pairs (i, j) of
 * pairs[2p], pairs[2p + 1], to be registered over `threads`. take sets
 * *taken and fills out when (i, j) from the frame's own vertices src is
 * the next announced pair, registering the batch that starts there if it
 * is not computed yet; else *taken is 0 and the caller registers it. */
int nricp_ahead_announce(nricp_method *m, const int *pairs, int n, int threads, tcb_error *err);
int nricp_ahead_take(nricp_method *m, const tcb_sequence *seq, int i, int j, const float *src, float *out,
                     int *taken, tcb_error *err);
void nricp_ahead_free(nricp_ahead *a);

/* deform_store.c: one finished chain per file. read fills c->outs of a
 * chain whose source, step and targets are set. */
int nricp_chain_path(const char *work_dir, const nricp_chain *c, char *path, size_t size, tcb_error *err);
int nricp_chain_write(const nricp_method *m, const nricp_chain *c, const char *path, tcb_error *err);
int nricp_chain_read(const nricp_method *m, nricp_chain *c, const char *path, tcb_error *err);

/* checkpoint.c */
uint64_t nricp_sequence_hash(const tcb_sequence *seq); /* FNV-1a of the vertices and block starts */
int nricp_save(void *self, const char *path, tcb_error *err);
/* The maps whose done[r] is 1 (done NULL: all of them) and the seconds
 * an unfinished fit has cost; read_state fills m->maps, done[2(F−1)] and
 * *fit_s of a prepared m. */
int nricp_write_state(const nricp_method *m, const unsigned char *done, double fit_s, const char *path,
                      tcb_error *err);
int nricp_read_state(nricp_method *m, unsigned char *done, double *fit_s, const char *path, tcb_error *err);
int nricp_load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err);

#endif

/* nricp — non-rigid ICP (Thea's Register, register.h) with the four
 * correspondence strategies of the paper's supp. "Analysis of nrICP"
 * (reference-protocol §6.3; TCSR's names in parentheses):
 *
 *   random              (random)              ν_{P_j}(P_i), then the harness's
 *                                             projection onto P_j (π_{P_j}).
 *                                             The paper's reported nrICP rows.
 *   propagate_simple    (propagate_many2one)  compose consecutive NN maps i → j
 *   propagate_bijective (propagate_hungarian) the same with linear assignments
 *   propagate_deform    (propagate_noproj)    X ← ν_{P_{k±1}}(X) through every
 *                                             frame between i and j
 *
 * The clouds are the GT vertices of each frame with area-weighted vertex
 * normals (§6.1: normals are required and only meshes have them). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/builtin.h"
#include "methods/nricp/deform_cost.h"
#include "methods/nricp/nricp_internal.h"
#include "methods/params.h"
#include "tcb/json.h"
#include "tcb/rng.h"
#include "tcb/split.h"

#define WHERE "nricp.params"

const char *const nricp_strategy_names[] = {"random", "propagate_simple", "propagate_bijective",
                                            "propagate_deform", NULL};

static int nricp_create(const char *params_json, void **self, tcb_error *err)
{
    static const char *const keys[] = {"strategy", "rounds", "smooth", "smooth_last", NULL};
    *self = NULL;
    cJSON *json;
    int rc = tcb_params_parse(params_json, WHERE, keys, &json, err);
    if (rc) return rc;
    nricp_params p = nricp_default_params();
    int strategy = 0;
    long long rounds = 0, smooth = 0, smooth_last = 0;
    rc = tcb_json_enum(json, "strategy", WHERE, 0, NRICP_RANDOM, nricp_strategy_names, &strategy, err);
    if (!rc) rc = tcb_json_int(json, "rounds", WHERE, 0, p.rounds, 1, 10000, &rounds, err);
    if (!rc) rc = tcb_json_int(json, "smooth", WHERE, 0, p.smooth, 0, 10000, &smooth, err);
    if (!rc) rc = tcb_json_int(json, "smooth_last", WHERE, 0, p.smooth_last, 0, 10000, &smooth_last, err);
    cJSON_Delete(json);
    if (rc) return rc;
    nricp_method *m = calloc(1, sizeof *m);
    if (!m) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    m->strategy = (nricp_strategy)strategy;
    m->params = p;
    m->params.rounds = (int)rounds, m->params.smooth = (int)smooth, m->params.smooth_last = (int)smooth_last;
    tcb_rng_seed_stream(&m->unit_pairs, 0, "nricp unit pairs");
    *self = m;
    return TCB_OK;
}

static int nricp_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    nricp_method *m = self;
    int rc = nricp_prepare(m, seq, err);
    if (!rc && nricp_uses_maps(m->strategy)) rc = nricp_fit_maps(m, seq, ctx, err);
    return rc;
}

static int compose_transfer(const nricp_method *m, const tcb_sequence *seq, int i, int j, float *out,
                            tcb_error *err)
{
    int32_t *idx = malloc((size_t)m->n_verts * sizeof *idx);
    if (!idx) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    nricp_compose(m, i, j, idx);
    const float *pj = tcb_seq_frame(seq, j);
    for (int v = 0; v < m->n_verts; v++)
        memcpy(out + 3 * (size_t)v, pj + 3 * (size_t)idx[v], 3 * sizeof *out);
    free(idx);
    return TCB_OK;
}

/* A pair of the fitted frames; the propagating chains run through
 * consecutive frames of one block. */
static int check_pair(const nricp_method *m, const tcb_sequence *seq, int i, int j, tcb_error *err)
{
    if (!m->normals || m->n_frames != seq->n_frames || m->n_verts != seq->n_verts)
        return tcb_fail(err, TCB_ERR_INTERNAL, "nricp: transfer before fit on sequence %s", seq->name);
    if (i < 0 || j < 0 || i >= m->n_frames || j >= m->n_frames)
        return tcb_fail(err, TCB_ERR_INPUT, "nricp: pair %d->%d outside frames 0..%d", i, j, m->n_frames - 1);
    int lo, hi;
    tcb_seq_block_of(seq, i, &lo, &hi);
    if (m->strategy != NRICP_RANDOM && (j < lo || j >= hi))
        return tcb_fail(err, TCB_ERR_INPUT, "nricp: %s: pair %d->%d crosses the block boundary of [%d, %d)",
                        nricp_strategy_names[m->strategy], i, j, lo, hi);
    return TCB_OK;
}

/* random registers the announced pairs ahead in parallel batches
 * (random_ahead.c), propagate_deform runs their chains at once (deform.c);
 * the propagating strategies have nothing to prepare. */
static int nricp_prepare_pairs(void *self, const tcb_sequence *seq, const int *pairs, int first, int n,
                               const tcb_fit_ctx *ctx, tcb_error *err)
{
    (void)first;
    nricp_method *m = self;
    if (nricp_uses_maps(m->strategy)) return TCB_OK;
    for (int p = 0; p < n; p++) {
        int rc = check_pair(m, seq, pairs[2 * p], pairs[2 * p + 1], err);
        if (rc) return rc;
    }
    if (m->strategy == NRICP_RANDOM) return nricp_ahead_announce(m, pairs, n, ctx->n_threads, err);
    return nricp_deform_pairs(m, seq, pairs, n, ctx, err);
}

static int nricp_transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n,
                          float *out, tcb_rng *rng, tcb_error *err)
{
    (void)rng; /* deterministic: the inputs are the GT vertices themselves */
    nricp_method *m = self;
    int rc = check_pair(m, seq, i, j, err);
    if (rc) return rc;
    /* Normals and vertex maps exist only for whole frames of GT vertices. */
    if (n != m->n_verts)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "nricp: can only transfer the %d GT vertices of a frame, got %d points", m->n_verts,
                        n);
    switch (m->strategy) {
    case NRICP_RANDOM: {
        int taken = 0;
        rc = nricp_ahead_take(m, seq, i, j, src, out, &taken, err);
        if (rc || taken) return rc;
        return nricp_register(src, nricp_normals_of(m, i), n, tcb_seq_frame(seq, j), nricp_normals_of(m, j), n,
                              &m->params, out, err);
    }
    case NRICP_SIMPLE:
    case NRICP_BIJECTIVE:
        return compose_transfer(m, seq, i, j, out, err);
    case NRICP_DEFORM:
        return nricp_deform_transfer(m, seq, i, j, src, out, err);
    }
    return tcb_fail(err, TCB_ERR_INTERNAL, "nricp: unknown strategy %d", (int)m->strategy);
}

/* The costs `tcbench calibrate` measures (tcb_method_ops.units), with the
 * default params, on its sequence: a registration between the frames of
 * a random pair (drawn as a split draws them: registrations between
 * frames further apart take longer), one between consecutive frames (a
 * propagating map's; a deform chain's step, which starts from the
 * deformed previous frame, is priced as one), and the dense assignment of
 * a frame's vertices to the next's (propagate_bijective's matching). Each
 * run draws its frames anew (seeded at create), so that a unit's runs
 * average over the sequence's pairs, as a cell's pairs do. */
static const char *const unit_names[] = {"register_random", "register_neighbor", "assign", NULL};
enum { UNIT_RANDOM, UNIT_NEIGHBOR, UNIT_ASSIGN };
/* A registration costs about its points x rounds (the old typed-in model,
 * crane against the synthetic walk); an assignment grows as n^2.3
 * (bench_lap's squared-distance costs). */
#define REGISTER_EXPONENT 1.0
#define ASSIGN_EXPONENT 2.3

static int nricp_run_unit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, int unit, tcb_error *err)
{
    (void)ctx; /* one registration or assignment runs on one thread */
    nricp_method *m = self;
    int rc = m->normals && m->n_frames == seq->n_frames && m->n_verts == seq->n_verts ? TCB_OK
                                                                                      : nricp_prepare(m, seq, err);
    /* random: an ordered pair of distinct frames, as a split draws it; else a frame and the next */
    int f = seq->n_frames, a = (int)tcb_rng_below(&m->unit_pairs, (uint32_t)(unit == UNIT_RANDOM ? f : f - 1));
    int b = unit == UNIT_RANDOM ? tcb_pair_sample(TCB_PAIRS_RANDOM, 0, f, 0, f, a, &m->unit_pairs) : a + 1;
    int nv = seq->n_verts;
    float *out = rc ? NULL : malloc((size_t)nv * 3 * sizeof *out);
    int32_t *map = rc ? NULL : malloc((size_t)nv * sizeof *map);
    if (!rc && (!out || !map)) rc = tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    if (!rc && unit == UNIT_ASSIGN) rc = nricp_assign(tcb_seq_frame(seq, a), tcb_seq_frame(seq, b), nv, map, err);
    else if (!rc)
        rc = nricp_register(tcb_seq_frame(seq, a), nricp_normals_of(m, a), nv, tcb_seq_frame(seq, b),
                            nricp_normals_of(m, b), nv, &m->params, out, err);
    free(out), free(map);
    return rc;
}

/* The units a cell runs, each on one thread, spread over the cell's
 * threads: the maps (registrations, and for bijective assignments;
 * maps.c), random's registration of each pair (random_ahead.c), a deform
 * chain's steps (deform.c). Registrations scale with the rounds over the
 * default's. */
static void nricp_estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out)
{
    const nricp_method *m = self;
    const char *name = nricp_strategy_names[m->strategy];
    if (q->n_verts < 1 || q->n_frames < 2) {
        out->fit_s = out->eval_s = -1;
        snprintf(out->basis, sizeof out->basis, "%s: grows with the vertex count (data absent)", name);
        return;
    }
    double rounds = (double)m->params.rounds / nricp_default_params().rounds;
    double threads = q->n_threads > 1 ? q->n_threads : 1, maps = 2.0 * (q->n_frames - 1) / threads;
    tcb_unit_use *u = out->units;
    out->fit_s = out->eval_s = 0;
    snprintf(out->basis, sizeof out->basis, "%s", name);
    if (m->strategy == NRICP_RANDOM)
        u[out->n_units++] = (tcb_unit_use){"register_random", 0, q->n_pairs * rounds / threads, REGISTER_EXPONENT, 1};
    if (nricp_uses_maps(m->strategy))
        u[out->n_units++] = (tcb_unit_use){"register_neighbor", maps * rounds, 0, REGISTER_EXPONENT, 1};
    if (m->strategy == NRICP_BIJECTIVE) u[out->n_units++] = (tcb_unit_use){"assign", maps, 0, ASSIGN_EXPONENT, 1};
    if (m->strategy == NRICP_DEFORM)
        u[out->n_units++] = (tcb_unit_use){"register_neighbor", 0,
                                           nricp_deform_expected_steps(q->n_frames, q->n_pairs) * rounds / threads,
                                           REGISTER_EXPONENT, 1};
}

static void nricp_destroy(void *self)
{
    nricp_method *m = self;
    if (!m) return;
    free(m->normals);
    free(m->maps);
    nricp_chains_free(&m->chains);
    nricp_ahead_free(&m->ahead);
    free(m);
}

const tcb_method_ops tcb_method_nricp = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "nricp",
    .description = "non-rigid ICP (Thea Register: 25 rounds, smooth 3/1) with the paper's four strategies",
    .create = nricp_create,
    .fit = nricp_fit,
    .transfer = nricp_transfer,
    .save = nricp_save,
    .load = nricp_load,
    .destroy = nricp_destroy,
    .estimate = nricp_estimate,
    .prepare_pairs = nricp_prepare_pairs,
    .units = unit_names,
    .run_unit = nricp_run_unit,
};

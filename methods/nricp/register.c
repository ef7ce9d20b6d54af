/* Thea's Register, after reference-protocol §6.2. Notation: source S =
 * {(p_i, n_i)}, target T = {(q_j, m_j)}; forward offsets d_i move p_i onto
 * T, backward offsets e_j move q_j onto S. An offset is "valid" once a
 * compatible point was found for it; an invalid one counts as zero and is
 * skipped by the smoothing (the protocol's "invalid (zero)" offsets).
 *
 *   init   d, e from the bounding-box alignment of the two clouds
 *   round r = 0 … R−1:
 *     r > 0      d_i ← q_nn(p_i + d_i) − p_i                (snap forward)
 *     r < R−1    r > 0: e_j ← p_nn(q_j + e_j) − q_j        (snap backward)
 *                smooth e (`smooth` times, target graph)
 *                d_i ← ½ d_i − ½ e_j°, j° = nn of p_i in {q_j + e_j}
 *                smooth d (`smooth` times, source graph)
 *     r = R−1    smooth d (`smooth_last` times)
 *   result p_i + d_i
 *
 * Every nearest-neighbour query is normal-compatible (knn_compat.h). */
#include "methods/nricp/register.h"

#include <math.h>
#include <stdlib.h>

#include "methods/nricp/knn_compat.h"

/* Kernel constant 0.5·(D+2)/V_D with D = 6 and V_6 = π³/6, the unit
 * 6-ball's volume (the Epanechnikov normalisation Thea uses). */
#define KERNEL_C 0.774037

/* A bounding-box extent below this fraction of the clouds' largest extent
 * counts as zero (a planar or linear cloud). */
#define FLAT_EXTENT 1e-9

typedef struct cloud {
    const float *p;    /* [n][3] positions */
    const float *nrm;  /* [n][3] normals */
    int n;
    nricp_compat_index *ix; /* index over p and nrm */
    int k;             /* graph row width */
    int32_t *nbr;      /* [n][k] graph: ≤ k nearest compatible points, self included */
    int *nbr_cnt;      /* [n] */
    float *w;          /* [n][k] smoothing weights of the graph edges */
} cloud;

typedef struct offsets {
    float *v;          /* [n][3] */
    unsigned char *ok; /* [n] valid */
} offsets;

/* Scratch shared by the steps, sized for the larger cloud. */
typedef struct scratch {
    float *pts;        /* [n][3] query positions or a transformed cloud */
    int32_t *idx;      /* [n] */
    int *cnt;          /* [n] */
    offsets tmp;       /* Jacobi double buffer */
    nricp_compat_index *deformed; /* the deformed target's index, built by the first blend */
} scratch;

/* ---- input checks ------------------------------------------------------- */

static int check_cloud(const float *p, const float *nrm, int n, const char *what, tcb_error *err)
{
    if (n <= 0 || !p || !nrm) return tcb_fail(err, TCB_ERR_INPUT, "nricp: the %s cloud is empty", what);
    if (n == 1)
        return tcb_fail(err, TCB_ERR_INPUT, "nricp: the %s cloud has a single point (need at least 2)", what);
    int spread = 0, oriented = 0;
    for (int i = 0; i < n; i++) {
        const float *a = p + 3 * (size_t)i, *b = nrm + 3 * (size_t)i;
        for (int c = 0; c < 3; c++) {
            if (!isfinite(a[c]) || fabsf(a[c]) > 1e18f)
                return tcb_fail(err, TCB_ERR_INPUT, "nricp: %s point %d is not finite (or beyond ±1e18)",
                                what, i);
            if (!isfinite(b[c]))
                return tcb_fail(err, TCB_ERR_INPUT, "nricp: %s normal %d is not finite", what, i);
            spread |= a[c] != p[c];
            oriented |= b[c] != 0.0f;
        }
    }
    if (!spread) return tcb_fail(err, TCB_ERR_INPUT, "nricp: all %d %s points coincide", n, what);
    if (!oriented) return tcb_fail(err, TCB_ERR_INPUT, "nricp: all %d %s normals are zero", n, what);
    return TCB_OK;
}

/* ---- small vector helpers ------------------------------------------------ */

static inline float dist2(const float *a, const float *b)
{
    float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return dx * dx + dy * dy + dz * dz;
}

static int offsets_alloc(offsets *o, int n)
{
    o->v = calloc((size_t)n * 3, sizeof *o->v);
    o->ok = calloc((size_t)n, 1);
    return o->v && o->ok;
}

static void offsets_free(offsets *o) { free(o->v), free(o->ok); }

/* out[i] = base[i] + o[i] (an invalid offset is zero). */
static void apply_offsets(const float *base, const offsets *o, int n, float *out)
{
    for (size_t x = 0; x < 3 * (size_t)n; x++) out[x] = base[x] + o->v[x];
}

/* ---- the neighbour graph and its kernel weights ------------------------- */

/* h_i² = 4·(distance to the farthest kept neighbour)², w = c·max(0, 1 − r²/h²).
 * When every neighbour coincides with p_i (h = 0) they all get the full c. */
static void graph_weights(cloud *c)
{
    for (int i = 0; i < c->n; i++) {
        const float *pi = c->p + 3 * (size_t)i;
        const int32_t *nb = c->nbr + (size_t)i * c->k;
        float *w = c->w + (size_t)i * c->k;
        int m = c->nbr_cnt[i];
        double h2 = m > 0 ? 4.0 * dist2(c->p + 3 * (size_t)nb[m - 1], pi) : 0.0;
        for (int a = 0; a < m; a++) {
            double r2 = dist2(c->p + 3 * (size_t)nb[a], pi);
            double t = h2 > 0.0 ? 1.0 - r2 / h2 : 1.0;
            w[a] = (float)(KERNEL_C * (t > 0.0 ? t : 0.0));
        }
    }
}

/* Index and graph of one cloud. Thea asks its kd-tree for 24 compatible
 * neighbours and keeps the first ≤ 8 by distance: the same set as the 8
 * nearest compatible ones, which is what is queried here. */
static int cloud_init(cloud *c, const float *p, const float *nrm, int n, int k, tcb_error *err)
{
    *c = (cloud){.p = p, .nrm = nrm, .n = n, .k = k < n ? k : n};
    c->nbr = malloc((size_t)n * c->k * sizeof *c->nbr);
    c->nbr_cnt = malloc((size_t)n * sizeof *c->nbr_cnt);
    c->w = malloc((size_t)n * c->k * sizeof *c->w);
    if (!c->nbr || !c->nbr_cnt || !c->w) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    int rc = nricp_compat_build(p, nrm, n, &c->ix, err);
    if (!rc) rc = nricp_knn_compat(c->ix, p, nrm, n, c->k, c->nbr, NULL, c->nbr_cnt, err);
    if (!rc) graph_weights(c);
    return rc;
}

static void cloud_free(cloud *c)
{
    nricp_compat_free(c->ix);
    free(c->nbr), free(c->nbr_cnt), free(c->w);
}

/* ---- smoothing ------------------------------------------------------------ */

/* One Jacobi iteration: d_i ← (d_i + Σ_{j∈N(i), d_j valid} w_ij d_j) / (1 + Σ w_ij),
 * with i ∈ N(i) (so self weight 1 + c). An invalid d_i enters with weight 0;
 * a point with no neighbour at all ends invalid (Thea's quirk). */
static void smooth_once(const cloud *c, const offsets *in, offsets *out)
{
    for (int i = 0; i < c->n; i++) {
        const int32_t *nb = c->nbr + (size_t)i * c->k;
        const float *w = c->w + (size_t)i * c->k;
        double acc[3] = {0, 0, 0}, wsum = 0.0;
        if (c->nbr_cnt[i] > 0 && in->ok[i]) {
            for (int x = 0; x < 3; x++) acc[x] = in->v[3 * (size_t)i + x];
            wsum = 1.0;
        }
        for (int a = 0; a < c->nbr_cnt[i]; a++) {
            if (!in->ok[nb[a]]) continue;
            for (int x = 0; x < 3; x++) acc[x] += w[a] * (double)in->v[3 * (size_t)nb[a] + x];
            wsum += w[a];
        }
        out->ok[i] = wsum > 0.0;
        for (int x = 0; x < 3; x++) out->v[3 * (size_t)i + x] = wsum > 0.0 ? (float)(acc[x] / wsum) : 0.0f;
    }
}

static void smooth(const cloud *c, offsets *o, offsets *tmp, int iters)
{
    for (int it = 0; it < iters; it++) {
        smooth_once(c, o, tmp);
        offsets t = *o;
        *o = *tmp;
        *tmp = t;
    }
}

/* ---- nearest compatible points -------------------------------------------- */

/* o_i ← to.p[nn] − base_i, nn = the point of `to` nearest to queries[i]
 * whose normal is compatible with from_nrm[i]; invalid when there is none.
 * `index` is an index over to.p itself or over a moved copy of it (same ids
 * and normals). */
static int snap(const nricp_compat_index *index, const cloud *to, const float *queries, const float *base,
                const float *from_nrm, int nq, offsets *o, scratch *s, tcb_error *err)
{
    int rc = nricp_knn_compat(index, queries, from_nrm, nq, 1, s->idx, NULL, s->cnt, err);
    for (int i = 0; !rc && i < nq; i++) {
        o->ok[i] = s->cnt[i] > 0;
        for (int x = 0; x < 3; x++)
            o->v[3 * (size_t)i + x] =
                o->ok[i] ? to->p[3 * (size_t)s->idx[i] + x] - base[3 * (size_t)i + x] : 0.0f;
    }
    return rc;
}

/* Snap the cloud `from` displaced by o onto `to` (the per-round update). */
static int snap_update(const cloud *from, const cloud *to, offsets *o, scratch *s, tcb_error *err)
{
    apply_offsets(from->p, o, from->n, s->pts);
    return snap(to->ix, to, s->pts, from->p, from->nrm, from->n, o, s, err);
}

/* ---- bounding-box initialisation ------------------------------------------ */

typedef struct bbox {
    double c[3], e[3]; /* centre, extent */
} bbox;

static bbox bbox_of(const float *p, int n)
{
    double lo[3], hi[3];
    for (int x = 0; x < 3; x++) lo[x] = hi[x] = p[x];
    for (int i = 1; i < n; i++)
        for (int x = 0; x < 3; x++) {
            double v = p[3 * (size_t)i + x];
            lo[x] = v < lo[x] ? v : lo[x];
            hi[x] = v > hi[x] ? v : hi[x];
        }
    bbox b;
    for (int x = 0; x < 3; x++) b.c[x] = 0.5 * (lo[x] + hi[x]), b.e[x] = hi[x] - lo[x];
    return b;
}

/* Per-axis scale taking box a onto box b; 1 on every axis when either box
 * is flat along some axis (anisotropic scaling skipped, as in Thea). */
static void bbox_scale(const bbox *a, const bbox *b, double s[3])
{
    double big = 0.0;
    for (int x = 0; x < 3; x++) big = fmax(big, fmax(a->e[x], b->e[x]));
    int flat = 0;
    for (int x = 0; x < 3; x++) flat |= a->e[x] <= FLAT_EXTENT * big || b->e[x] <= FLAT_EXTENT * big;
    for (int x = 0; x < 3; x++) s[x] = flat ? 1.0 : b->e[x] / a->e[x];
}

/* out = A_{a→b}(p): c_b + (e_b ⊘ e_a) ⊙ (p − c_a). */
static void bbox_map(const bbox *a, const bbox *b, const float *p, int n, float *out)
{
    double s[3];
    bbox_scale(a, b, s);
    for (int i = 0; i < n; i++)
        for (int x = 0; x < 3; x++)
            out[3 * (size_t)i + x] = (float)(b->c[x] + s[x] * (p[3 * (size_t)i + x] - a->c[x]));
}

/* o_i = to.p[j*] − from.p_i, j* = argmin over compatible j of
 * ||from.p_i − A_{to→from}(to.p_j)||: the offset uses the untransformed point. */
static int bbox_offsets(const cloud *from, const cloud *to, offsets *o, scratch *s, tcb_error *err)
{
    bbox bf = bbox_of(from->p, from->n), bt = bbox_of(to->p, to->n);
    bbox_map(&bt, &bf, to->p, to->n, s->pts);
    nricp_compat_index *moved;
    int rc = nricp_compat_build(s->pts, to->nrm, to->n, &moved, err);
    if (rc) return rc;
    rc = snap(moved, to, from->p, from->p, from->nrm, from->n, o, s, err);
    nricp_compat_free(moved);
    return rc;
}

/* ---- blending ---------------------------------------------------------------- */

/* d_i ← ½ d_i − ½ e_j°, j° = the compatible point of the deformed target
 * {q_j + e_j} nearest to p_i. An invalid d_i takes −e_j° whole; an invalid
 * e_j° (or no compatible j°) leaves d_i as it is. */
static int blend(const cloud *S, const cloud *T, offsets *d, const offsets *e, scratch *s,
                 tcb_error *err)
{
    apply_offsets(T->p, e, T->n, s->pts);
    int rc = TCB_OK;
    if (s->deformed) nricp_compat_move(s->deformed, s->pts);
    else rc = nricp_compat_build(s->pts, T->nrm, T->n, &s->deformed, err);
    if (!rc) rc = nricp_knn_compat(s->deformed, S->p, S->nrm, S->n, 1, s->idx, NULL, s->cnt, err);
    for (int i = 0; !rc && i < S->n; i++) {
        if (!s->cnt[i] || !e->ok[s->idx[i]]) continue;
        const float *ej = e->v + 3 * (size_t)s->idx[i];
        float *di = d->v + 3 * (size_t)i;
        for (int x = 0; x < 3; x++) di[x] = d->ok[i] ? 0.5f * di[x] - 0.5f * ej[x] : -ej[x];
        d->ok[i] = 1;
    }
    return rc;
}

/* ---- the rounds ---------------------------------------------------------------- */

static int run_rounds(const cloud *S, const cloud *T, const nricp_params *p, offsets *d,
                      offsets *e, scratch *s, tcb_error *err)
{
    int rc = bbox_offsets(S, T, d, s, err);
    if (!rc) rc = bbox_offsets(T, S, e, s, err);
    for (int r = 0; !rc && r < p->rounds; r++) {
        if (r > 0) rc = snap_update(S, T, d, s, err);
        if (rc) break;
        if (r == p->rounds - 1) {
            smooth(S, d, &s->tmp, p->smooth_last);
            break;
        }
        if (r > 0) rc = snap_update(T, S, e, s, err);
        if (rc) break;
        smooth(T, e, &s->tmp, p->smooth);
        rc = blend(S, T, d, e, s, err);
        if (!rc) smooth(S, d, &s->tmp, p->smooth);
    }
    return rc;
}

static int check_params(const nricp_params *p, tcb_error *err)
{
    if (p->rounds < 1) return tcb_fail(err, TCB_ERR_INPUT, "nricp: rounds must be ≥ 1, got %d", p->rounds);
    if (p->smooth < 0 || p->smooth_last < 0)
        return tcb_fail(err, TCB_ERR_INPUT, "nricp: smooth and smooth_last must be ≥ 0, got %d and %d",
                        p->smooth, p->smooth_last);
    if (p->k < 1) return tcb_fail(err, TCB_ERR_INPUT, "nricp: k must be ≥ 1, got %d", p->k);
    return TCB_OK;
}

int nricp_register(const float *src, const float *src_nrm, int n_src, const float *dst,
                   const float *dst_nrm, int n_dst, const nricp_params *p, float *out,
                   tcb_error *err)
{
    int rc = check_params(p, err);
    if (!rc) rc = check_cloud(src, src_nrm, n_src, "source", err);
    if (!rc) rc = check_cloud(dst, dst_nrm, n_dst, "target", err);
    if (rc) return rc;
    int n = n_src > n_dst ? n_src : n_dst;
    cloud S = {0}, T = {0};
    offsets d = {0}, e = {0};
    scratch s = {malloc((size_t)n * 3 * sizeof(float)), malloc((size_t)n * sizeof(int32_t)),
                 malloc((size_t)n * sizeof(int)), {0}, NULL};
    if (!s.pts || !s.idx || !s.cnt || !offsets_alloc(&s.tmp, n) || !offsets_alloc(&d, n_src) ||
        !offsets_alloc(&e, n_dst))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for %d + %d points", n_src, n_dst);
    if (!rc) rc = cloud_init(&S, src, src_nrm, n_src, p->k, err);
    if (!rc) rc = cloud_init(&T, dst, dst_nrm, n_dst, p->k, err);
    if (!rc) rc = run_rounds(&S, &T, p, &d, &e, &s, err);
    if (!rc) apply_offsets(src, &d, n_src, out);
    cloud_free(&S), cloud_free(&T);
    offsets_free(&d), offsets_free(&e), offsets_free(&s.tmp);
    free(s.pts), free(s.idx), free(s.cnt);
    nricp_compat_free(s.deformed);
    return rc;
}

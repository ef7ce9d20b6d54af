/* PDG's objective and its gradient (methods/pdg/objective.h). */
#include "methods/pdg/objective.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/robust_chamfer.h"

/* Field g moves frame src onto frame dst, away from the keyframe. */
static int src_frame(int g, int key) { return g < key ? g + 1 : g; }
static int dst_frame(int g, int key) { return g < key ? g : g + 1; }

/* One chain from the keyframe: dir −1 (toward frame 0) or +1. Step m
 * (1-based) samples field_of(m) and reaches frame_of(m). */
typedef struct chain {
    int dir, len;
    float *x;    /* [len + 1][nv][3]: x⁰ = v, …, x^len */
    float *s;    /* [len][nv][C]: each step's level mean, for the backward */
    float *grad; /* [len + 1][nv][3]: ∂loss/∂x^m */
    float *A;    /* cayley: [len][nv][12] A^1 … A^len (x^m = A^m v; A⁰ = I); else NULL */
    float *gA;   /* cayley: [len][nv][12] ∂loss/∂A^m from the steps after m; else NULL */
} chain;

static int field_of(int key, int dir, int m) { return dir < 0 ? key - m : key + m - 1; }
static int frame_of(int key, int dir, int m) { return dir < 0 ? key - m : key + m; }

static void chains_free(chain c[2])
{
    for (int k = 0; k < 2; k++) free(c[k].x), free(c[k].s), free(c[k].grad), free(c[k].A), free(c[k].gA);
    memset(c, 0, 2 * sizeof *c);
}

/* Step m's carry into *buf (NULL when released: the chain's points are all
 * a translation carries). */
static const tcb_pdg_carry *carry_at(const tcb_pdg_fields *f, const tcb_pdg_problem *p, const chain *c, int m,
                                     tcb_pdg_carry *buf)
{
    if (f->rotation == TCB_PDG_RELEASED) return NULL;
    size_t at = (size_t)p->nv * TCB_PDG_AFFINE;
    *buf = (tcb_pdg_carry){.x0 = p->template_verts,
                           .A = m > 1 ? c->A + (m - 2) * at : NULL,
                           .A_out = c->A + (m - 1) * at,
                           .dA_out = c->gA && m < c->len ? c->gA + (m - 1) * at : NULL,
                           .dA = c->gA && m > 1 ? c->gA + (m - 2) * at : NULL};
    return buf;
}

/* Both chains run forward from v, their gradients zeroed (none kept
 * without grads: the read-out). */
static int chains_run(const tcb_pdg_fields *f, const float *V, const tcb_pdg_problem *p, int grads, chain c[2],
                      tcb_error *err)
{
    memset(c, 0, 2 * sizeof *c);
    size_t frame = (size_t)p->nv * 3, na = f->rotation == TCB_PDG_CAYLEY ? (size_t)p->nv * TCB_PDG_AFFINE : 0;
    for (int k = 0; k < 2; k++) {
        c[k].dir = k ? 1 : -1;
        c[k].len = k ? p->n - 1 - p->key : p->key;
        size_t steps = (size_t)(c[k].len ? c[k].len : 1);
        c[k].x = malloc((size_t)(c[k].len + 1) * frame * sizeof *c[k].x);
        c[k].s = malloc(steps * p->nv * f->C * sizeof *c[k].s);
        c[k].grad = grads ? calloc((size_t)(c[k].len + 1) * frame, sizeof *c[k].grad) : NULL;
        c[k].A = na ? malloc(steps * na * sizeof *c[k].A) : NULL;
        c[k].gA = na && grads ? calloc(steps * na, sizeof *c[k].gA) : NULL;
        if (!c[k].x || !c[k].s || (grads && !c[k].grad) || (na && !c[k].A) || (na && grads && !c[k].gA)) {
            chains_free(c);
            return tcb_fail(err, TCB_ERR_NOMEM, "pdg: out of memory for the chains");
        }
        memcpy(c[k].x, p->template_verts, frame * sizeof *c[k].x);
        for (int m = 1; m <= c[k].len; m++) {
            tcb_pdg_carry buf;
            tcb_pdg_field_forward(f, V, field_of(p->key, c[k].dir, m), c[k].x + (m - 1) * frame, p->nv,
                                  carry_at(f, p, &c[k], m, &buf), c[k].s + (size_t)(m - 1) * p->nv * f->C,
                                  c[k].x + m * frame);
        }
    }
    return TCB_OK;
}

int tcb_pdg_propagate(const tcb_pdg_fields *f, const float *V, const tcb_pdg_problem *p, float *X, tcb_error *err)
{
    chain c[2];
    int rc = chains_run(f, V, p, 0, c, err);
    if (rc) return rc;
    size_t frame = (size_t)p->nv * 3;
    for (int k = 0; k < 2; k++)
        for (int m = k; m <= c[k].len; m++) /* the keyframe once: v */
            memcpy(X + (size_t)frame_of(p->key, c[k].dir, m) * frame, c[k].x + m * frame, frame * sizeof *X);
    chains_free(c);
    return TCB_OK;
}

/* L_in and its gradient into dV. */
static int input_term(const tcb_pdg_fields *f, const float *V, const tcb_pdg_problem *p, const tcb_pdg_weights *w,
                      double *L, float *dV, tcb_error *err)
{
    int T = p->n - 1, most = 0;
    for (int t = 0; t < p->n; t++) most = p->n_points[t] > most ? p->n_points[t] : most;
    float *y = malloc((size_t)most * 3 * sizeof *y), *s = malloc((size_t)most * f->C * sizeof *s),
          *dy = malloc((size_t)most * 3 * sizeof *dy), *ds = malloc((size_t)most * f->C * sizeof *ds);
    int rc = y && s && dy && ds ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "pdg: out of memory");
    *L = 0.0;
    for (int g = 0; !rc && g < T; g++) {
        int a = src_frame(g, p->key), b = dst_frame(g, p->key), n = p->n_points[a];
        tcb_pdg_field_forward(f, V, g, p->points[a], n, NULL, s, y);
        double cd;
        rc = tcb_robust_chamfer(y, n, p->points[b], p->n_points[b], p->points_index[b], w->alpha, &cd, dy, err);
        if (rc) break;
        *L += cd / T;
        for (size_t i = 0; i < (size_t)n * 3; i++) dy[i] /= (float)T;
        tcb_pdg_field_backward(f, V, g, p->points[a], n, NULL, s, dy, dV, NULL, ds);
    }
    free(y), free(s), free(dy), free(ds);
    return rc;
}

/* Σ_e |ℓ_e(x) − ℓ_e(prev)| / ne, and with coef ≠ 0 its gradient times coef
 * into dx and (unless dprev is NULL) dprev. prev_len: ℓ(prev) given (the
 * template's), else computed from prev. */
static double edge_change(const tcb_pdg_problem *p, const float *x, const float *prev, const float *prev_len,
                          double coef, float *dx, float *dprev)
{
    double sum = 0.0;
    for (int e = 0; e < p->ne; e++) {
        int a = p->edges[2 * e], b = p->edges[2 * e + 1];
        double d[3], dp[3], len = 0.0, plen = 0.0;
        for (int k = 0; k < 3; k++) {
            d[k] = (double)x[3 * a + k] - x[3 * b + k], len += d[k] * d[k];
            dp[k] = (double)prev[3 * a + k] - prev[3 * b + k], plen += dp[k] * dp[k];
        }
        len = sqrt(len), plen = prev_len ? prev_len[e] : sqrt(plen);
        double diff = len - plen;
        sum += fabs(diff);
        if (coef == 0.0 || diff == 0.0) continue; /* |·|' = 0 at 0, as PyTorch's */
        double sg = coef * (diff > 0 ? 1.0 : -1.0);
        for (int k = 0; k < 3 && len > 0; k++) {
            dx[3 * a + k] += (float)(sg * d[k] / len);
            dx[3 * b + k] -= (float)(sg * d[k] / len);
        }
        for (int k = 0; k < 3 && dprev && plen > 0; k++) {
            dprev[3 * a + k] -= (float)(sg * dp[k] / plen);
            dprev[3 * b + k] += (float)(sg * dp[k] / plen);
        }
    }
    return sum / p->ne;
}

/* The chain terms on the chains' positions: values into out, direct
 * gradients into each chain's grad. */
static int chain_terms(const tcb_pdg_problem *p, const tcb_pdg_weights *w, long long epoch, long long epochs,
                       double L_in, chain c[2], tcb_pdg_loss *out, tcb_error *err)
{
    size_t frame = (size_t)p->nv * 3;
    int M = c[0].len > c[1].len ? c[0].len : c[1].len;
    float *dcd = malloc(frame * sizeof *dcd);
    if (!dcd) return tcb_fail(err, TCB_ERR_NOMEM, "pdg: out of memory");
    double e = 1.0 - sqrt((double)epoch / (double)epochs), s = 1.0, S = 0.0;
    int rc = TCB_OK;
    out->pred = out->edge = 0.0;
    for (int m = 1; !rc && m <= M; m++) {
        int live = (c[0].len >= m) + (c[1].len >= m);
        double cd[2] = {0, 0}, weight = pow(s, e), CD = 0.0;
        for (int k = 0; !rc && k < 2; k++) {
            if (c[k].len < m) continue;
            int t = frame_of(p->key, c[k].dir, m);
            float *x = c[k].x + m * frame, *g = c[k].grad + m * frame;
            rc = tcb_robust_chamfer(x, p->nv, p->points[t], p->n_points[t], p->points_index[t], w->alpha, &cd[k], dcd,
                                    err);
            if (rc) break;
            CD += cd[k] / live;
            float k_cd = (float)(weight / (M * live));
            for (size_t i = 0; i < frame; i++) g[i] += k_cd * dcd[i];
            double k_e = w->edge / ((double)M * live * p->ne);
            out->edge += w->edge / M / live *
                         edge_change(p, x, x - frame, m == 1 ? p->template_edge_len : NULL, k_e, g,
                                     m == 1 ? NULL : g - frame);
        }
        out->pred += weight * CD / M;
        S += weight * CD; /* the catch-up: the next step's weight shrinks as the chain falls behind L_in */
        s /= fmax(1.0, 1.0 + S - L_in);
    }
    free(dcd);
    return rc;
}

int tcb_pdg_loss_grad(const tcb_pdg_fields *f, const float *V, const tcb_pdg_problem *p, const tcb_pdg_weights *w,
                      long long epoch, long long epochs, tcb_pdg_loss *out, float *dV, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    memset(dV, 0, f->off[f->levels] * sizeof *dV);
    if (p->n < 2 || p->key < 0 || p->key >= p->n || p->n - 1 != f->T)
        return tcb_fail(err, TCB_ERR_INPUT, "pdg: %d frames, keyframe %d, %d fields", p->n, p->key, f->T);
    int rc = input_term(f, V, p, w, &out->input, dV, err);
    out->total = out->input;
    if (rc || epoch < w->warmup) return rc;
    chain c[2];
    if ((rc = chains_run(f, V, p, 1, c, err))) return rc;
    rc = chain_terms(p, w, epoch, epochs, out->input, c, out, err);
    size_t frame = (size_t)p->nv * 3, each = (size_t)p->nv * f->C;
    float *ds = rc ? NULL : malloc(each * sizeof *ds);
    if (!rc && !ds) rc = tcb_fail(err, TCB_ERR_NOMEM, "pdg: out of memory");
    for (int k = 0; !rc && k < 2; k++) /* back along each chain; x⁰ = v is held constant */
        for (int m = c[k].len; m >= 1; m--) {
            tcb_pdg_carry buf;
            tcb_pdg_field_backward(f, V, field_of(p->key, c[k].dir, m), c[k].x + (m - 1) * frame, p->nv,
                                   carry_at(f, p, &c[k], m, &buf), c[k].s + (m - 1) * each, c[k].grad + m * frame, dV,
                                   m > 1 ? c[k].grad + (m - 1) * frame : NULL, ds);
        }
    free(ds);
    chains_free(c);
    out->total = out->input + out->pred + out->edge;
    return rc;
}

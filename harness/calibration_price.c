/* A cell's cost from the calibrations (harness/calibration.h): a cost at
 * any thread count from the counts measured, and a method's estimate
 * priced with it. */
#include <math.h>
#include <string.h>

#include "harness/calibration.h"

#define MAX_COUNTS 64 /* thread counts of one (kind, method, preset) */

typedef struct cost_curve {
    int n, threads[MAX_COUNTS];
    double seconds[MAX_COUNTS];
} cost_curve;

/* The measurements of (kind, method, preset) in c by increasing thread
 * count (a count measured twice: the later). */
static void curve_of(const tcb_calibration *c, tcb_cost_kind kind, const char *method, const char *preset,
                     cost_curve *out)
{
    out->n = 0;
    for (int k = 0; k < c->n; k++) {
        const tcb_cost_entry *e = &c->entries[k];
        if (e->kind != kind || strcmp(e->method, method) || strcmp(e->preset, preset)) continue;
        int at = 0;
        while (at < out->n && out->threads[at] < e->threads) at++;
        if (at < out->n && out->threads[at] == e->threads) {
            out->seconds[at] = e->seconds;
            continue;
        }
        if (out->n == MAX_COUNTS) continue;
        memmove(out->threads + at + 1, out->threads + at, (size_t)(out->n - at) * sizeof *out->threads);
        memmove(out->seconds + at + 1, out->seconds + at, (size_t)(out->n - at) * sizeof *out->seconds);
        out->threads[at] = e->threads, out->seconds[at] = e->seconds, out->n++;
    }
}

/* The exponent b of seconds ∝ threads^b between measurements a and a + 1;
 * clamped to [-1, 0] for extrapolation: at best linear scaling, and more
 * threads never slower. */
static double exponent(const cost_curve *c, int a, int clamp)
{
    double b = log(c->seconds[a + 1] / c->seconds[a]) / log((double)c->threads[a + 1] / c->threads[a]);
    return clamp ? fmin(0, fmax(-1, b)) : b;
}

static void price_curve(const cost_curve *c, int threads, tcb_cost_price *out)
{
    int a = 0;
    while (a + 1 < c->n && c->threads[a + 1] <= threads) a++;
    out->extrapolated = threads < c->threads[0] || threads > c->threads[c->n - 1];
    if (c->n == 1 || c->threads[a] == threads) {
        out->seconds = c->seconds[a];
        out->lo = out->hi = c->threads[a];
        if (c->n == 1) out->lo = out->hi = c->threads[0];
        return;
    }
    if (a + 1 == c->n) a--; /* beyond the last: the last two's scaling, from the last */
    int from = threads > c->threads[a + 1] ? a + 1 : a;
    out->lo = c->threads[a], out->hi = c->threads[a + 1];
    out->seconds = c->seconds[from] * pow((double)threads / c->threads[from], exponent(c, a, out->extrapolated));
}

int tcb_cost_lookup(const tcb_calibration_set *s, tcb_cost_kind kind, const char *method, const char *preset,
                    int threads, tcb_cost_price *out)
{
    memset(out, 0, sizeof *out);
    for (int k = 0; k < s->n; k++) {
        cost_curve c;
        curve_of(&s->c[k], kind, method, preset, &c);
        if (!c.n) continue;
        price_curve(&c, threads < 1 ? 1 : threads, out);
        out->from = &s->c[k];
        return 0;
    }
    return -1;
}

/* "2 threads" / "3 threads interpolated from 2-4" / "16 threads extrapolated from 1-2". */
static void threads_text(const tcb_cost_price *p, int threads, char *out, size_t size)
{
    const char *how = p->extrapolated ? "extrapolated" : "interpolated";
    if (p->lo == p->hi && p->lo == threads) snprintf(out, size, "%d thread%s", threads, threads == 1 ? "" : "s");
    else if (p->lo == p->hi) snprintf(out, size, "%d threads extrapolated: only %d measured", threads, p->lo);
    else snprintf(out, size, "%d threads %s from %d-%d", threads, how, p->lo, p->hi);
}

static void unknown(tcb_cost_estimate *e, const char *what, const char *method, const char *preset)
{
    e->fit_s = e->eval_s = -1;
    snprintf(e->basis, sizeof e->basis, "no %s of %.24s preset %.16s measured: tcbench calibrate --only %.24s --preset %.16s",
             what, method, preset, method, preset);
}

/* The harness's scoring of q's pairs at q's vertex count; -1: unknown. */
static double score_seconds(const tcb_calibration_set *s, const tcb_cost_query *q)
{
    tcb_cost_price p;
    if (q->n_verts < 1 || tcb_cost_lookup(s, TCB_COST_SCORE_PAIR, "", "", q->n_threads, &p)) return -1;
    double r = (double)q->n_verts / p.from->n_verts;
    return q->n_pairs * p.seconds * r * r;
}

/* fit_s, eval_s (without the scoring) and basis of a method naming a preset. */
static void price_preset(const tcb_calibration_set *s, const char *method, const tcb_cost_query *q,
                         tcb_cost_estimate *e)
{
    tcb_cost_price step, pair;
    if (tcb_cost_lookup(s, TCB_COST_STEP, method, e->preset, q->n_threads, &step)) {
        unknown(e, "step cost", method, e->preset);
        return;
    }
    if (tcb_cost_lookup(s, TCB_COST_EVAL_PAIR, method, e->preset, q->n_threads, &pair)) {
        unknown(e, "evaluation cost", method, e->preset);
        return;
    }
    char threads[64];
    threads_text(&step, q->n_threads, threads, sizeof threads);
    e->fit_s = (double)e->steps * step.seconds;
    e->eval_s = q->n_pairs * pair.seconds;
    snprintf(e->basis, sizeof e->basis, "%lld steps x %.1f ms (%.60s, %.80s)", e->steps, step.seconds * 1e3, threads,
             step.from->machine);
}

void tcb_cost_price_cell(const tcb_calibration_set *s, const char *method, const tcb_cost_query *q,
                         tcb_cost_estimate *e)
{
    if (e->preset[0]) price_preset(s, method, q, e);
    if (e->eval_s < 0) return;
    double score = score_seconds(s, q);
    e->eval_s = score < 0 ? -1 : e->eval_s + score;
}

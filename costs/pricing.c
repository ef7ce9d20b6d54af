/* A cell's cost from the calibrations (costs/calibration.h): a cost at
 * any thread count from the counts measured, and a method's estimate
 * priced with it. */
#include <math.h>
#include <string.h>

#include "costs/calibration.h"

#define MAX_COUNTS 64 /* thread counts of one (kind, method, preset) */

typedef struct cost_curve {
    int n, threads[MAX_COUNTS];
    double seconds[MAX_COUNTS];
    int vertices; /* of the sequence measured on */
} cost_curve;

/* The measurements of key in c by increasing thread count (a count
 * measured twice: the later); a surface frame's per sample of a mesh, so
 * that counts measured at other sizes compare. */
static void curve_of(const tcb_calibration *c, const tcb_cost_key *key, cost_curve *out)
{
    const char *sequence = key->sequence ? key->sequence : "";
    out->n = 0;
    for (int k = 0; k < c->n; k++) {
        const tcb_cost_entry *e = &c->entries[k];
        if (e->kind != key->kind || strcmp(e->method, key->method) || strcmp(e->preset, key->preset) ||
            strcmp(e->unit, key->unit) || strcmp(e->sequence, sequence))
            continue;
        out->vertices = e->sequence[0] ? e->vertices : c->n_verts;
        double seconds = e->size > 0 ? e->seconds / e->size : e->seconds;
        int at = 0;
        while (at < out->n && out->threads[at] < e->threads) at++;
        if (at < out->n && out->threads[at] == e->threads) {
            out->seconds[at] = seconds;
            continue;
        }
        if (out->n == MAX_COUNTS) continue;
        memmove(out->threads + at + 1, out->threads + at, (size_t)(out->n - at) * sizeof *out->threads);
        memmove(out->seconds + at + 1, out->seconds + at, (size_t)(out->n - at) * sizeof *out->seconds);
        out->threads[at] = e->threads, out->seconds[at] = seconds, out->n++;
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

/* key's cost on exactly key->sequence ("" the calibration sequence's). */
static int lookup_exact(const tcb_calibration_set *s, const tcb_cost_key *key, int threads, tcb_cost_price *out)
{
    for (int k = 0; k < s->n; k++) {
        cost_curve c;
        curve_of(&s->c[k], key, &c);
        if (!c.n) continue;
        price_curve(&c, threads < 1 ? 1 : threads, out);
        out->from = &s->c[k];
        out->vertices = c.vertices;
        return 0;
    }
    return -1;
}

int tcb_cost_lookup(const tcb_calibration_set *s, const tcb_cost_key *key, int threads, tcb_cost_price *out)
{
    memset(out, 0, sizeof *out);
    tcb_cost_key general = *key;
    general.sequence = NULL;
    out->on_sequence = key->sequence && key->sequence[0] && !lookup_exact(s, key, threads, out);
    return out->on_sequence ? 0 : lookup_exact(s, &general, threads, out);
}

/* "2 threads" / "3 threads interpolated from 2-4" / "16 threads extrapolated from 1-2". */
static void threads_text(const tcb_cost_price *p, int threads, char *out, size_t size)
{
    const char *how = p->extrapolated ? "extrapolated" : "interpolated";
    if (p->lo == p->hi && p->lo == threads) snprintf(out, size, "%d thread%s", threads, threads == 1 ? "" : "s");
    else if (p->lo == p->hi) snprintf(out, size, "%d threads extrapolated: only %d measured", threads, p->lo);
    else snprintf(out, size, "%d threads %s from %d-%d", threads, how, p->lo, p->hi);
}

/* Unknown: fit_s and eval_s -1, basis why and the command that measures it. */
static void unknown(tcb_cost_estimate *e, const char *what, const char *method, const char *preset)
{
    e->fit_s = e->eval_s = -1;
    snprintf(e->basis, sizeof e->basis, "no %.40s of %.24s%s%.16s measured: tcbench calibrate --only %.24s%s%.16s", what,
             method, preset[0] ? " preset " : "", preset, method, preset[0] ? " --preset " : "", preset);
}

static void data_absent(tcb_cost_estimate *e, const char *grows)
{
    e->fit_s = e->eval_s = -1;
    snprintf(e->basis, sizeof e->basis, "grows with the %s (data absent)", grows);
}

/* The harness's scoring of q's pairs at q's vertex count, measured on the
 * cell's sequence where a calibration has it (*own set); -1: unknown. */
static double score_seconds(const tcb_calibration_set *s, const char *sequence, const tcb_cost_query *q, int *own)
{
    tcb_cost_price p;
    const tcb_cost_key key = {TCB_COST_SCORE_PAIR, "", "", "", sequence};
    if (q->n_verts < 1 || tcb_cost_lookup(s, &key, q->n_threads, &p)) return -1;
    *own = p.on_sequence;
    double r = (double)q->n_verts / p.vertices;
    return q->n_pairs * p.seconds * r * r;
}

/* fit_s, eval_s (without the scoring) and basis of a method naming a
 * preset; 0 when it is unknown. */
static int price_preset(const tcb_calibration_set *s, const char *method, const tcb_cost_query *q,
                        tcb_cost_estimate *e)
{
    tcb_cost_price step, pair;
    const tcb_cost_key step_key = {TCB_COST_STEP, method, e->preset, "", NULL};
    const tcb_cost_key pair_key = {TCB_COST_EVAL_PAIR, method, e->preset, "", NULL};
    if (tcb_cost_lookup(s, &step_key, q->n_threads, &step)) {
        unknown(e, "step cost", method, e->preset);
        return 0;
    }
    if (tcb_cost_lookup(s, &pair_key, q->n_threads, &pair)) {
        unknown(e, "evaluation cost", method, e->preset);
        return 0;
    }
    if (e->step_frames && q->n_frames < 1) {
        data_absent(e, "frame count: a step is an epoch over every frame");
        return 0;
    }
    /* an epoch's step was measured over the calibration sequence's frames */
    double frames = e->step_frames ? (double)q->n_frames / step.from->n_frames : 1;
    char threads[64];
    threads_text(&step, q->n_threads, threads, sizeof threads);
    e->fit_s = (double)e->steps * step.seconds * frames;
    /* a pair carries every vertex of its source frame: linear in the count */
    e->eval_s = q->n_pairs * pair.seconds * (q->n_verts > 0 ? (double)q->n_verts / pair.vertices : 1);
    snprintf(e->basis, sizeof e->basis, "%lld steps x %.1f ms%s (%.60s, %.80s)", e->steps,
             step.seconds * frames * 1e3, e->step_frames ? " at its frames" : "", threads, step.from->machine);
    return 1;
}

/* One unit use's seconds into *fit, *eval, from its cost measured on the
 * cell's sequence where there is one (p->on_sequence), else on the
 * calibration sequence; 0 when unknown (e says why). */
static int price_unit(const tcb_calibration_set *s, const char *method, const char *sequence,
                      const tcb_cost_query *q, const tcb_unit_use *u, tcb_cost_estimate *e, double *fit, double *eval,
                      tcb_cost_price *p)
{
    const tcb_cost_key key = {TCB_COST_UNIT, method, e->preset, u->unit, sequence};
    if (tcb_cost_lookup(s, &key, u->threads > 0 ? u->threads : q->n_threads, p)) {
        char what[64];
        snprintf(what, sizeof what, "unit %.31s", u->unit);
        unknown(e, what, method, e->preset);
        return 0;
    }
    if (u->exponent != 0 && q->n_verts < 1) {
        data_absent(e, "vertex count");
        return 0;
    }
    double each = p->seconds * (u->exponent != 0 ? pow((double)q->n_verts / p->vertices, u->exponent) : 1);
    *fit = u->fit * each, *eval = u->eval * each;
    return 1;
}

/* The units' seconds added to fit_s and eval_s; the basis names the
 * costliest unit (and the sequence it was measured on, when the cell's):
 * after the steps' basis when there is one (which names the machine), else
 * after the method's own words with its threads and machine. 0 when one is
 * unknown. */
static int price_units(const tcb_calibration_set *s, const char *method, const char *sequence,
                       const tcb_cost_query *q, tcb_cost_estimate *e)
{
    double most = -1;
    char costliest[192] = "";
    int n = e->n_units < TCB_MAX_UNIT_USES ? e->n_units : TCB_MAX_UNIT_USES, after_steps = e->basis[0] && e->steps;
    for (int k = 0; k < n; k++) {
        const tcb_unit_use *u = &e->units[k];
        double fit, eval;
        tcb_cost_price p;
        if (!price_unit(s, method, sequence, q, u, e, &fit, &eval, &p)) return 0;
        e->fit_s += fit, e->eval_s += eval;
        if (fit + eval <= most) continue;
        char threads[64];
        most = fit + eval;
        threads_text(&p, u->threads > 0 ? u->threads : q->n_threads, threads, sizeof threads);
        /* a whole count as a number, not in exponent form: "140000 frame", not "1.4e+05 frame" */
        double count = u->fit + u->eval;
        int len = snprintf(costliest, sizeof costliest, count == floor(count) && count < 1e15 ? "%.0f %.31s x %.3g s"
                                                                                              : "%.4g %.31s x %.3g s",
                           count, u->unit, fit + eval > 0 ? (fit + eval) / count : 0.0);
        if (p.on_sequence && len > 0 && (size_t)len < sizeof costliest)
            len += snprintf(costliest + len, sizeof costliest - (size_t)len, " measured on %.60s", sequence);
        if (!after_steps && len > 0 && (size_t)len < sizeof costliest)
            snprintf(costliest + len, sizeof costliest - (size_t)len, " (%.40s, %.50s)", threads, p.from->machine);
    }
    size_t len = strlen(e->basis);
    if (n && len + 4 < sizeof e->basis)
        snprintf(e->basis + len, sizeof e->basis - len, "%s%s", len ? (after_steps ? " + " : ": ") : "", costliest);
    return 1;
}

/* The reconstruction metrics of the frames q's pairs use (expected
 * distinct frames of 2 n_pairs uniform draws: clips' consecutive frames
 * use fewer): the method's surface of each and the harness's part at
 * `samples` per mesh; -1 unknown, -2 not measured. */
static double surface_seconds(const tcb_calibration_set *s, const char *method, const char *preset,
                              const tcb_cost_query *q, int samples)
{
    tcb_cost_price harness, mesh;
    const tcb_cost_key frame_key = {TCB_COST_SURFACE_FRAME, method, preset, "", NULL};
    const tcb_cost_key mesh_key = {TCB_COST_SURFACE_MESH, method, preset, "", NULL};
    if (tcb_cost_lookup(s, &frame_key, q->n_threads, &harness) || tcb_cost_lookup(s, &mesh_key, q->n_threads, &mesh))
        return -2;
    if (q->n_frames < 1) return -1;
    double f = q->n_frames, frames = f * (1 - pow(1 - 1 / f, 2.0 * q->n_pairs));
    return frames * (mesh.seconds + harness.seconds * samples);
}

/* The reconstruction metrics added to eval_s; a method whose surface frame
 * is not measured keeps eval_s without them, and the basis says so. */
static void add_surface(const tcb_calibration_set *s, const char *method, const tcb_cost_query *q, int samples,
                        tcb_cost_estimate *e)
{
    double t = surface_seconds(s, method, e->preset, q, samples);
    size_t len = strlen(e->basis);
    if (t >= 0) e->eval_s += t;
    else if (t < -1.5 && len + 4 < sizeof e->basis)
        snprintf(e->basis + len, sizeof e->basis - len, "; reconstruction metrics not measured: tcbench calibrate "
                 "--only %.24s%s%.16s", method, e->preset[0] ? " --preset " : "", e->preset);
    else e->eval_s = -1;
}

void tcb_cost_price_cell(const tcb_calibration_set *s, const char *method, const char *sequence,
                         const tcb_cost_query *q, int surface_samples, tcb_cost_estimate *e)
{
    if (e->preset[0] && e->steps > 0 && !price_preset(s, method, q, e)) return;
    if (e->n_units > 0 && !price_units(s, method, sequence, q, e)) return;
    if (e->eval_s < 0) return;
    if (surface_samples > 0) add_surface(s, method, q, surface_samples, e);
    if (e->eval_s < 0) return;
    int own = 0;
    double score = score_seconds(s, sequence, q, &own);
    e->eval_s = score < 0 ? -1 : e->eval_s + score;
    size_t len = strlen(e->basis);
    if (own && len + 40 < sizeof e->basis)
        snprintf(e->basis + len, sizeof e->basis - len, "; scoring measured on %s", sequence);
}

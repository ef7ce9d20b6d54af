/* Calibrations (costs/calibration.h): a cost at any thread count from
 * the counts measured (exact, interpolated as a power law, extrapolated
 * with the last two's scaling clamped to [linear, flat]), the first
 * calibration that measured a method wins, a cell priced from them (steps,
 * steps over every frame, units scaled with the vertex count, the
 * reconstruction metrics of the frames used; a config's sequence's units
 * and scoring for that sequence only), the file written and read back,
 * and malformed files named. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "costs/calibration.h"
#include "testutil.h"

/* unit: kind unit's name; size: kind surface_frame's samples. */
static void add_sized(tcb_calibration *c, tcb_cost_kind kind, const char *method, const char *preset,
                      const char *unit, int size, int threads, double s)
{
    tcb_cost_entry e = {.kind = kind, .threads = threads, .samples = 1, .seconds = s, .size = size};
    snprintf(e.method, sizeof e.method, "%s", method);
    snprintf(e.preset, sizeof e.preset, "%s", preset);
    snprintf(e.unit, sizeof e.unit, "%s", unit);
    tcb_error err = {0};
    assert_int_equal(tcb_calibration_add(c, &e, &err), TCB_OK);
}

static void add(tcb_calibration *c, tcb_cost_kind kind, const char *method, const char *preset, int threads,
                double s)
{
    add_sized(c, kind, method, preset, "", 0, threads, s);
}

static int lookup(const tcb_calibration_set *s, tcb_cost_kind kind, const char *method, const char *preset,
                  int threads, tcb_cost_price *p)
{
    const tcb_cost_key key = {kind, method, preset, "", NULL};
    return tcb_cost_lookup(s, &key, threads, p);
}

/* A set of one calibration: m/p steps of 8 s at 1 thread, 5 at 2, 2 at 8. */
static void one(tcb_calibration_set *s)
{
    memset(s, 0, sizeof *s);
    s->n = 1;
    snprintf(s->c[0].machine, sizeof s->c[0].machine, "first");
    s->c[0].n_verts = 1000, s->c[0].n_frames = 6;
    add(&s->c[0], TCB_COST_STEP, "m", "p", 8, 2);
    add(&s->c[0], TCB_COST_STEP, "m", "p", 1, 8);
    add(&s->c[0], TCB_COST_STEP, "m", "p", 2, 5);
}

/* one() with m/p's pairs at 0.25 s and the scoring at 0.01 s, 1 thread. */
static void priced(tcb_calibration_set *s)
{
    one(s);
    add(&s->c[0], TCB_COST_EVAL_PAIR, "m", "p", 1, 0.25);
    add(&s->c[0], TCB_COST_SCORE_PAIR, "", "", 1, 0.01);
}

static tcb_cost_estimate of_preset(const char *preset, long long steps)
{
    tcb_cost_estimate e = {.steps = steps};
    snprintf(e.preset, sizeof e.preset, "%s", preset);
    return e;
}

/* e priced unknown, its basis saying `why`. */
static void assert_unknown(const tcb_calibration_set *s, const char *method, const tcb_cost_query *q,
                           tcb_cost_estimate e, const char *why)
{
    tcb_cost_price_cell(s, method, NULL, q, 0, &e);
    assert_true(e.fit_s < 0 && e.eval_s < 0);
    if (!strstr(e.basis, why)) fail_msg("'%s' lacks '%s'", e.basis, why);
}

static double price(const tcb_calibration_set *s, int threads, int *extrapolated)
{
    tcb_cost_price p;
    assert_int_equal(lookup(s, TCB_COST_STEP, "m", "p", threads, &p), 0);
    *extrapolated = p.extrapolated;
    return p.seconds;
}

static void test_thread_scaling(void **state)
{
    (void)state;
    tcb_calibration_set s;
    one(&s);
    int ex;
    assert_near(price(&s, 2, &ex), 5, 1e-12);
    assert_false(ex);
    /* between 2 and 8: 5 * (4/2)^b, b = log(2/5)/log(4) */
    assert_near(price(&s, 4, &ex), 5 * pow(2, log(0.4) / log(4)), 1e-12);
    assert_false(ex);
    /* beyond 8: the 2..8 exponent (-0.66) goes on */
    assert_near(price(&s, 32, &ex), 2 * pow(4, log(0.4) / log(4)), 1e-12);
    assert_true(ex);
    /* a measured superlinear scaling is clamped to linear beyond it */
    add(&s.c[0], TCB_COST_STEP, "m", "p", 16, 0.5);
    assert_near(price(&s, 64, &ex), 0.5 / 4, 1e-12);
    assert_true(ex);
    /* and slower with more threads is clamped to flat */
    add(&s.c[0], TCB_COST_STEP, "m", "p", 32, 0.9);
    assert_near(price(&s, 64, &ex), 0.9, 1e-12);
    /* a count measured again: the later measurement */
    add(&s.c[0], TCB_COST_STEP, "m", "p", 2, 4);
    assert_near(price(&s, 2, &ex), 4, 1e-12);
    tcb_calibration_set_free(&s);
}

static void test_single_count_and_first_match(void **state)
{
    (void)state;
    tcb_calibration_set s;
    one(&s);
    s.n = 2;
    snprintf(s.c[1].machine, sizeof s.c[1].machine, "second");
    add(&s.c[1], TCB_COST_STEP, "m", "p", 1, 100);
    add(&s.c[1], TCB_COST_STEP, "other", "p", 2, 3);
    tcb_cost_price p;
    /* m/p is in the first: the second's is not mixed in */
    assert_int_equal(lookup(&s, TCB_COST_STEP, "m", "p", 1, &p), 0);
    assert_near(p.seconds, 8, 1e-12);
    assert_string_equal(p.from->machine, "first");
    /* other/p only in the second, at one count: that cost, extrapolated */
    assert_int_equal(lookup(&s, TCB_COST_STEP, "other", "p", 16, &p), 0);
    assert_near(p.seconds, 3, 1e-12);
    assert_true(p.extrapolated);
    assert_string_equal(p.from->machine, "second");
    assert_int_equal(lookup(&s, TCB_COST_STEP, "m", "q", 1, &p), -1);
    assert_int_equal(lookup(&s, TCB_COST_EVAL_PAIR, "m", "p", 1, &p), -1);
    tcb_calibration_set_free(&s);
}

static void test_price_cell(void **state)
{
    (void)state;
    tcb_calibration_set s;
    priced(&s);
    tcb_cost_query q = {10, 2000, 100, 1};
    tcb_cost_estimate e = of_preset("p", 1000);
    tcb_cost_price_cell(&s, "m", NULL, &q, 0, &e);
    assert_near(e.fit_s, 8000, 1e-9);
    /* 100 pairs x (0.25 x 2000/1000 + 0.01 x (2000/1000)^2): the method's
     * part linear in the vertex count, the scoring's quadratic */
    assert_near(e.eval_s, 100 * (0.5 + 0.04), 1e-9);
    assert_non_null(strstr(e.basis, "1000 steps x 8000.0 ms (1 thread, first)"));
    /* a method naming no preset keeps its own fit and gets the scoring added */
    tcb_cost_estimate own = {.fit_s = 3, .eval_s = 1};
    tcb_cost_price_cell(&s, "x", NULL, &q, 0, &own);
    assert_near(own.fit_s, 3, 0);
    assert_near(own.eval_s, 1 + 100 * 0.04, 1e-9);
    /* a preset not measured: unknown, with the command that measures it */
    assert_unknown(&s, "m", &q, of_preset("big", 5), "tcbench calibrate --only m --preset big");
    tcb_calibration_set_free(&s);
}

/* A fit of epochs over every frame (step_frames) and a one-off unit of
 * the preset: 10 steps x 8 s x 12/6 frames + 3 s. */
static void test_price_epochs_and_unit(void **state)
{
    (void)state;
    tcb_calibration_set s;
    priced(&s);
    add_sized(&s.c[0], TCB_COST_UNIT, "m", "p", "template", 0, 1, 3);
    tcb_cost_query q = {12, 1000, 4, 1};
    tcb_cost_estimate e = of_preset("p", 10);
    e.step_frames = 1, e.n_units = 1;
    e.units[0] = (tcb_unit_use){"template", 1, 0, 0, 0};
    tcb_cost_price_cell(&s, "m", NULL, &q, 0, &e);
    assert_near(e.fit_s, 10 * 8 * 2 + 3, 1e-9);
    assert_near(e.eval_s, 4 * (0.25 + 0.01), 1e-9);
    assert_non_null(strstr(e.basis, "10 steps x 16000.0 ms at its frames (1 thread, first) + 1 template x 3 s"));
    /* the frame count unknown: so is the fit */
    tcb_cost_query absent = {0, 0, 4, 1};
    e.n_units = 0;
    assert_unknown(&s, "m", &absent, e, "grows with the frame count");
    tcb_calibration_set_free(&s);
}

/* A method without presets pricing its cells by units only, as nricp: a
 * registration per pair (exponent 1) and assignments (exponent 2.3), at
 * one thread each, from a calibration at 1000 vertices. */
static void test_price_units(void **state)
{
    (void)state;
    tcb_calibration_set s;
    one(&s);
    add(&s.c[0], TCB_COST_SCORE_PAIR, "", "", 2, 0.01);
    add_sized(&s.c[0], TCB_COST_UNIT, "r", "", "register_random", 0, 1, 2.0);
    add_sized(&s.c[0], TCB_COST_UNIT, "r", "", "register_random", 0, 2, 1.5);
    add_sized(&s.c[0], TCB_COST_UNIT, "r", "", "assign", 0, 1, 0.5);
    tcb_cost_query q = {10, 2000, 100, 2};
    tcb_cost_estimate e = {.n_units = 2};
    snprintf(e.basis, sizeof e.basis, "random");
    e.units[0] = (tcb_unit_use){"register_random", 0, 100, 1, 1};
    e.units[1] = (tcb_unit_use){"assign", 9, 0, 2.3, 1};
    tcb_cost_price_cell(&s, "r", NULL, &q, 0, &e);
    /* 9 x 0.5 s x 2^2.3 = 22.16 s; 100 x 2 s x 2 (the one-thread cost) plus the scoring, 100 x 0.01 x 2^2 */
    assert_near(e.fit_s, 9 * 0.5 * 4.924577653379665, 1e-9);
    assert_near(e.eval_s, 100 * 2.0 * 2 + 4, 1e-9);
    assert_non_null(strstr(e.basis, "random: 100 register_random x 4 s (1 thread, first)"));
    /* a unit not measured: the command, without a preset */
    tcb_cost_estimate none = {.n_units = 1};
    none.units[0] = (tcb_unit_use){"register_neighbor", 1, 0, 1, 1};
    assert_unknown(&s, "r", &q, none, "no unit register_neighbor of r measured: tcbench calibrate --only r");
    tcb_cost_price_cell(&s, "r", NULL, &q, 0, &none);
    assert_null(strstr(none.basis, "--preset"));
    /* a unit growing with the vertex count, the data absent */
    tcb_cost_query absent = {0, 0, 100, 2};
    tcb_cost_estimate a = {.n_units = 1};
    a.units[0] = e.units[0];
    assert_unknown(&s, "r", &absent, a, "grows with the vertex count");
    tcb_calibration_set_free(&s);
}

/* A one-thread cost of method's unit (kind unit) or of a pair's scoring
 * (unit NULL) measured on `sequence` of nv vertices. */
static void add_on(tcb_calibration *c, const char *method, const char *unit, double s, const char *sequence, int nv)
{
    if (unit) add_sized(c, TCB_COST_UNIT, method, "", unit, 0, 1, s);
    else add(c, TCB_COST_SCORE_PAIR, "", "", 1, s);
    snprintf(c->entries[c->n - 1].sequence, sizeof c->entries[0].sequence, "%s", sequence);
    c->entries[c->n - 1].vertices = nv;
}

/* Units and the scoring measured on a config's sequence price that
 * sequence's cells (scaled from its own vertex count) over the calibration
 * sequence's, and only that sequence's; the basis says so. */
static void test_price_on_sequence(void **state)
{
    (void)state;
    tcb_calibration_set s;
    one(&s);
    /* the calibration sequence's (1000 vertices), then crane-like ones: 4 s
     * a registration at 4000 vertices, 0.3 s a pair's scoring */
    add_on(&s.c[0], "r", "register_random", 2.0, "", 0);
    add_on(&s.c[0], "r", NULL, 0.01, "", 0);
    add_on(&s.c[0], "r", "register_random", 4.0, "d/long", 4000);
    add_on(&s.c[0], "r", NULL, 0.3, "d/long", 4000);
    tcb_cost_query q = {10, 2000, 100, 1};
    tcb_cost_estimate e = {.n_units = 1};
    snprintf(e.basis, sizeof e.basis, "random");
    e.units[0] = (tcb_unit_use){"register_random", 0, 100, 1, 1};
    tcb_cost_estimate other = e;
    tcb_cost_price_cell(&s, "r", "d/long", &q, 0, &e);
    /* 100 x 4 s x 2000/4000, and 100 x 0.3 s x (2000/4000)^2 */
    assert_near(e.eval_s, 100 * 4.0 * 0.5 + 100 * 0.3 * 0.25, 1e-9);
    if (!strstr(e.basis, "random: 100 register_random x 2 s measured on d/long (1 thread, first); scoring measured "
                         "on d/long"))
        fail_msg("'%s'", e.basis);
    /* another sequence: the calibration sequence's costs, from its 1000 vertices */
    tcb_cost_price_cell(&s, "r", "d/short", &q, 0, &other);
    assert_near(other.eval_s, 100 * 2.0 * 2 + 100 * 0.01 * 4, 1e-9);
    assert_null(strstr(other.basis, "measured on"));
    tcb_calibration_set_free(&s);
}

/* The reconstruction metrics: the method's mesh of a frame, and the
 * harness's part per sample of a mesh from a frame measured at 1000
 * samples, for the frames the pairs use: 2 frames and 1 pair draw
 * 1.5 distinct frames on average ((0,0) (0,1) (1,0) (1,1): 1, 2, 2, 1). */
static void test_price_surface(void **state)
{
    (void)state;
    tcb_calibration_set s;
    priced(&s);
    add_sized(&s.c[0], TCB_COST_SURFACE_FRAME, "m", "p", "", 1000, 1, 2.0);
    add(&s.c[0], TCB_COST_SURFACE_MESH, "m", "p", 1, 0.5);
    tcb_cost_query q = {2, 1000, 1, 1};
    tcb_cost_estimate e = of_preset("p", 1);
    tcb_cost_price_cell(&s, "m", NULL, &q, 500, &e);
    /* each frame: its mesh, 0.5 s, and the harness's part at half the samples */
    assert_near(e.eval_s, 0.25 + 1.5 * (0.5 + 2.0 * 500 / 1000) + 0.01, 1e-9);
    /* not measured (another preset): the evaluation without them, and said */
    add(&s.c[0], TCB_COST_STEP, "m", "p2", 1, 1);
    add(&s.c[0], TCB_COST_EVAL_PAIR, "m", "p2", 1, 0.25);
    tcb_cost_estimate o = of_preset("p2", 1);
    tcb_cost_price_cell(&s, "m", NULL, &q, 500, &o);
    assert_near(o.eval_s, 0.25 + 0.01, 1e-9);
    assert_non_null(strstr(o.basis, "reconstruction metrics not measured: tcbench calibrate --only m --preset p2"));
    tcb_calibration_set_free(&s);
}

static void test_file_round_trip(void **state)
{
    const char *dir = *state;
    tcb_calibration c = {0};
    snprintf(c.machine, sizeof c.machine, "CPU, 2 cores");
    c.machine_json = strdup("{\"summary\": \"CPU, 2 cores\", \"cores\": 2}");
    c.n_verts = 2688, c.n_frames = 6;
    add(&c, TCB_COST_STEP, "cc", "paper", 2, 2.91234567);
    add(&c, TCB_COST_SCORE_PAIR, "", "", 1, 0.0101);
    add_sized(&c, TCB_COST_UNIT, "nricp", "", "assign", 0, 1, 0.5);
    add_sized(&c, TCB_COST_SURFACE_FRAME, "atlasnet", "cpu", "", 100000, 2, 1.25);
    add_on(&c, "nricp", "register_random", 0.55, "ama/crane", 10002);
    char path[1024];
    snprintf(path, sizeof path, "%s/cal.json", dir);
    tcb_error err = {0};
    assert_int_equal(tcb_calibration_write(&c, path, &err), TCB_OK);
    tcb_calibration_free(&c);
    tcb_calibration_set s;
    assert_int_equal(tcb_calibration_set_load(dir, &s, &err), TCB_OK); /* no <dir>/calibration.json */
    int builtin = s.n;
    tcb_calibration_set_free(&s);
    char in_run[1024];
    snprintf(in_run, sizeof in_run, "%s/calibration.json", dir);
    assert_int_equal(rename(path, in_run), 0);
    assert_int_equal(tcb_calibration_set_load(dir, &s, &err), TCB_OK);
    assert_int_equal(s.n, builtin + 1);
    assert_string_equal(s.c[0].machine, "CPU, 2 cores");
    assert_int_equal(s.c[0].n_verts, 2688);
    assert_int_equal(s.c[0].n_frames, 6);
    assert_int_equal(s.c[0].n, 5);
    assert_near(s.c[0].entries[0].seconds, 2.912, 1e-12); /* 4 significant digits */
    assert_int_equal(s.c[0].entries[1].kind, TCB_COST_SCORE_PAIR);
    assert_int_equal(s.c[0].entries[2].kind, TCB_COST_UNIT);
    assert_string_equal(s.c[0].entries[2].unit, "assign");
    assert_int_equal(s.c[0].entries[3].kind, TCB_COST_SURFACE_FRAME);
    assert_int_equal(s.c[0].entries[3].size, 100000);
    assert_string_equal(s.c[0].entries[3].unit, "");
    assert_string_equal(s.c[0].entries[3].sequence, "");
    assert_string_equal(s.c[0].entries[4].sequence, "ama/crane");
    assert_int_equal(s.c[0].entries[4].vertices, 10002);
    tcb_calibration_set_free(&s);
}

static void test_malformed(void **state)
{
    (void)state;
    static const struct {
        const char *text, *message;
    } cases[] = {
        {"[]", "f.json: expected an object"},
        {"{\"format\": \"x\"}", "f.json: format: expected \"tcbench-calibration 1\""},
        {"{\"format\": \"tcbench-calibration 1\", \"machine\": {\"summary\": \"m\"}, \"sequence\": {\"vertices\": 9},"
         " \"costs\": [{\"kind\": \"step\", \"method\": \"a\", \"preset\": \"p\", \"threads\": 1, \"seconds\": -1,"
         " \"samples\": 1}]}",
         "f.json: costs[0].seconds"},
        {"{\"format\": \"tcbench-calibration 1\", \"machine\": {\"summary\": \"m\"}, \"sequence\": {\"vertices\": 9},"
         " \"costs\": [{\"kind\": \"walk\"}]}",
         "f.json: costs[0].kind"},
        {"{\"format\": \"tcbench-calibration 1\", \"machine\": {}, \"sequence\": {\"vertices\": 9}, \"costs\": []}",
         "f.json: machine.summary"},
        {"{\"format\": \"tcbench-calibration 1\", \"machine\": {\"summary\": \"m\"}, \"sequence\": {\"vertices\": 9},"
         " \"costs\": [{\"kind\": \"step\", \"method\": \"a\", \"preset\": \"p\", \"unit\": \"u\", \"threads\": 1,"
         " \"seconds\": 1, \"samples\": 1}]}",
         "f.json: costs[0].unit: only a cost of kind \"unit\" has one"},
        {"{\"format\": \"tcbench-calibration 1\", \"machine\": {\"summary\": \"m\"}, \"sequence\": {\"vertices\": 9},"
         " \"costs\": [{\"kind\": \"unit\", \"method\": \"a\", \"preset\": \"\", \"threads\": 1, \"seconds\": 1,"
         " \"samples\": 1}]}",
         "f.json: costs[0].unit"},
        {"{\"format\": \"tcbench-calibration 1\", \"machine\": {\"summary\": \"m\"}, \"sequence\": {\"vertices\": 9},"
         " \"costs\": [{\"kind\": \"surface_frame\", \"method\": \"a\", \"preset\": \"p\", \"threads\": 1,"
         " \"seconds\": 1, \"samples\": 1}]}",
         "f.json: costs[0].size"},
        {"{\"format\": \"tcbench-calibration 1\", \"machine\": {\"summary\": \"m\"}, \"sequence\": {\"vertices\": 9,"
         " \"frames\": 0}, \"costs\": []}",
         "f.json: sequence.frames"},
        {"{\"format\": \"tcbench-calibration 1\", \"machine\": {\"summary\": \"m\"}, \"sequence\": {\"vertices\": 9},"
         " \"costs\": [{\"kind\": \"unit\", \"method\": \"a\", \"preset\": \"\", \"unit\": \"u\", \"threads\": 1,"
         " \"seconds\": 1, \"samples\": 1, \"sequence\": \"d/s\"}]}",
         "f.json: costs[0].sequence: a cost measured on a sequence has both \"sequence\" and \"vertices\""},
        {"{\"format\": \"tcbench-calibration 1\", \"machine\": {\"summary\": \"m\"}, \"sequence\": {\"vertices\": 9},"
         " \"costs\": [{\"kind\": \"step\", \"method\": \"a\", \"preset\": \"p\", \"threads\": 1, \"seconds\": 1,"
         " \"samples\": 1, \"sequence\": \"d/s\", \"vertices\": 9}]}",
         "f.json: costs[0].sequence: only a cost of kind \"unit\" or \"score_pair\" has one"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        tcb_calibration c;
        tcb_error err = {0};
        assert_int_equal(tcb_calibration_parse(cases[k].text, "f.json", &c, &err), TCB_ERR_INPUT);
        if (!strstr(err.msg, cases[k].message)) fail_msg("case %zu: '%s'", k, err.msg);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_thread_scaling),
        cmocka_unit_test(test_single_count_and_first_match),
        cmocka_unit_test(test_price_cell),
        cmocka_unit_test(test_price_epochs_and_unit),
        cmocka_unit_test(test_price_units),
        cmocka_unit_test(test_price_on_sequence),
        cmocka_unit_test(test_price_surface),
        cmocka_unit_test_setup_teardown(test_file_round_trip, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_malformed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

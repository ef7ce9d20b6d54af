/* Reports from a fake run: two datasets; anim has a validation and two test
 * sequences, ama only a validation one; methods AN (reconstructs, 2 seeds),
 * NN (no reconstruction) and DSR (best on horse, failed on camel). Every
 * expected number is recomputed here from the raw per-vertex errors. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fake_run.h"
#include "tcb/fsutil.h"
#include "tcb/report.h"
#include "testutil.h"

typedef struct seq_spec {
    const char *dataset, *name, *role;
    double scale; /* error scale of the sequence: cat is hard */
} seq_spec;

static const seq_spec SEQS[] = {
    {"anim", "cat", "validation", 3.0},
    {"anim", "horse", "test", 1.0},
    {"anim", "camel", "test", 1.5},
    {"ama", "crane", "validation", 2.0},
};
#define N_SEQS 4

typedef struct method_spec {
    const char *name;
    double base;
    int has_cd, n_seeds;
} method_spec;

static const method_spec METHODS[] = {
    {"AN", 0.010, 1, 2}, {"NN", 0.020, 0, 1}, {"DSR", 0.005, 1, 1}};
#define N_METHODS 3

static fake_cell cell_of(int s, int m, int seed)
{
    const seq_spec *q = &SEQS[s];
    const method_spec *p = &METHODS[m];
    int failed = !strcmp(p->name, "DSR") && !strcmp(q->name, "camel");
    return (fake_cell){q->dataset, q->name, q->role, p->name, seed,
                       failed ? TCB_CELL_FAILED : TCB_CELL_OK, p->base * q->scale, p->has_cd, 0};
}

/* Expected table values of (sequence, method): [metric] mean and std in
 * table units, pooled over seeds by hand: m_sL2, rank, AUC, CD, m_geo,
 * AUC_geo; and the vertices scored by the geodesic fallback. */
#define N_COLS 6
typedef struct expect {
    double mean[N_COLS], std[N_COLS];
    int unreachable;
} expect;

static expect expected_seeds(int s, int m, int first_seed, int n_seeds)
{
    double sl2[8 * FAKE_PAIRS * FAKE_NV], rank[8 * FAKE_PAIRS * FAKE_NV];
    double geo[8 * FAKE_PAIRS * FAKE_NV], auc[8 * FAKE_PAIRS], cd[8 * FAKE_PAIRS];
    double geo_auc[8 * FAKE_PAIRS];
    int nv = 0, np = 0;
    expect e = {{0}, {0}, 0};
    for (int seed = first_seed; seed < first_seed + n_seeds; seed++) {
        fake_cell c = cell_of(s, m, seed);
        for (int p = 0; p < FAKE_PAIRS; p++, np++) {
            tcb_pair_metrics pm;
            fake_pair(&c, p, &pm);
            auc[np] = pm.auc;
            cd[np] = fake_cd(&c, p);
            geo_auc[np] = pm.geo_auc;
            e.unreachable += fake_unreachable(&c, p);
            for (int k = 0; k < FAKE_NV; k++, nv++) {
                sl2[nv] = fake_sl2(&c, p, k);
                rank[nv] = fake_rank(k);
                geo[nv] = fake_geo(&c, p, k);
            }
        }
    }
    fake_mean_std(sl2, nv, &e.mean[0], &e.std[0]);
    fake_mean_std(rank, nv, &e.mean[1], &e.std[1]);
    fake_mean_std(auc, np, &e.mean[2], &e.std[2]);
    fake_mean_std(cd, np, &e.mean[3], &e.std[3]);
    fake_mean_std(geo, nv, &e.mean[4], &e.std[4]);
    fake_mean_std(geo_auc, np, &e.mean[5], &e.std[5]);
    static const double scale[N_COLS] = {1e3, 1e2, 1e2, 1e3, 1e3, 1e2};
    for (int k = 0; k < N_COLS; k++) e.mean[k] *= scale[k], e.std[k] *= scale[k];
    return e;
}

static expect expected(int s, int m) { return expected_seeds(s, m, 0, METHODS[m].n_seeds); }

/* The dataset MEAN over the given sequences (§5.6: means and stds averaged
 * separately). */
static expect expected_mean(const int *seqs, int n, int m)
{
    expect e = {{0}, {0}, 0};
    for (int k = 0; k < n; k++) {
        expect s = expected(seqs[k], m);
        for (int j = 0; j < N_COLS; j++) e.mean[j] += s.mean[j] / n, e.std[j] += s.std[j] / n;
        e.unreachable += s.unreachable;
    }
    return e;
}

static const int DECIMALS[N_COLS] = {2, 2, 2, 3, 2, 2};

/* "| AN | **1.00 ± 0.20** | 3.00 ± 1.41 ≈ | … |" with `bold` and `tie` 6-bit
 * masks (significantly best; tied for best) and `no_cd` "-". */
static void md_row(const char *method, const expect *e, int bold, int tie, int no_cd, char *out,
                   size_t size)
{
    size_t used = (size_t)snprintf(out, size, "| %s |", method);
    for (int j = 0; j < N_COLS; j++) {
        const char *b = bold >> j & 1 ? "**" : "", *t = tie >> j & 1 ? " ≈" : "";
        if (j == 3 && no_cd)
            used += (size_t)snprintf(out + used, size - used, " - |");
        else
            used += (size_t)snprintf(out + used, size - used, " %s%.*f ± %.*f%s%s |", b, DECIMALS[j],
                                     e->mean[j], DECIMALS[j], e->std[j], b, t);
    }
}

/* Not inlined: GCC 12 inlining it next to strstr on its result warns of a
 * dangling pointer to its local `text` (a false positive). */
__attribute__((noinline)) static char *read_all(const char *path)
{
    char *text;
    tcb_error err = {0};
    if (tcb_read_file(path, &text, NULL, &err)) fail_msg("%s", err.msg);
    return text;
}

typedef struct fixture {
    char dir[512];
    char report[1024];
    char *md;
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    tu_make_tmpdir(f->dir, sizeof f->dir);
    for (int s = 0; s < N_SEQS; s++)
        for (int m = 0; m < N_METHODS; m++)
            for (int seed = 0; seed < METHODS[m].n_seeds; seed++) {
                fake_cell c = cell_of(s, m, seed);
                if (fake_write(f->dir, &c)) return -1;
            }
    snprintf(f->report, sizeof f->report, "%s/report", f->dir);
    char echo_path[4096];
    snprintf(echo_path, sizeof echo_path, "%s/echo.md", f->dir);
    FILE *echo = fopen(echo_path, "w");
    tcb_error err = {0};
    int rc = tcb_report_write(f->dir, NULL, echo, &err);
    fclose(echo);
    if (rc) {
        fprintf(stderr, "tcb_report_write: %s\n", err.msg);
        return -1;
    }
    char md_path[4096];
    snprintf(md_path, sizeof md_path, "%s/tables.md", f->report);
    f->md = read_all(md_path);
    char *echoed = read_all(echo_path);
    int same = !strcmp(echoed, f->md);
    free(echoed);
    *state = f;
    return same ? 0 : -1;
}

static int teardown(void **state)
{
    fixture *f = *state;
    free(f->md);
    tu_remove_tree(f->dir);
    free(f);
    return 0;
}

/* The text of the block headed `heading`, up to the next heading. */
static char *section(const char *md, const char *heading)
{
    const char *start = strstr(md, heading);
    if (!start) fail_msg("no section \"%s\"", heading);
    const char *end = strstr(start + strlen(heading), "\n### ");
    size_t n = end ? (size_t)(end - start) : strlen(start);
    char *s = malloc(n + 1);
    memcpy(s, start, n);
    s[n] = '\0';
    return s;
}

static void assert_contains(const char *text, const char *needle)
{
    if (!strstr(text, needle)) fail_msg("expected \"%s\" in:\n%s", needle, text);
}

static void test_md_sequence_block_bold_and_dash(void **state)
{
    fixture *f = *state;
    char *horse = section(f->md, "### anim / horse");
    char row[512];
    expect an = expected(1, 0), nn = expected(1, 1), dsr = expected(1, 2);
    /* DSR leads everywhere, but on 2 pairs no difference can be significant
     * (Wilcoxon's smallest p with n = 2 is 0.5): no bold, every row tied for
     * best where it has a value (NN has no CD). NN and DSR ran one of the
     * heading's two seeds, which their rows say. test_compare's
     * test_report_marks checks bold where differences are real. */
    md_row("AN", &an, 0, 0x3F, 0, row, sizeof row);
    assert_contains(horse, row);
    md_row("NN (seed 0)", &nn, 0, 0x37, 1, row, sizeof row);
    assert_contains(horse, row);
    md_row("DSR (seed 0)", &dsr, 0, 0x3F, 0, row, sizeof row);
    assert_contains(horse, row);
    assert_contains(horse, "≈: tied for best");
    assert_contains(horse, "A method with one seed: its intervals cover the sampling of pairs only");
    assert_null(strstr(horse, "| AN ("));
    assert_contains(horse, "role: test · pairs: 2 · seeds: 0, 1");
    /* Links to the block's plots, which test_pngs_are_valid finds on disk. */
    assert_contains(horse, "![PCK curves](pck_anim_horse.png) "
                           "![geodesic PCK curves](pck_geo_anim_horse.png) "
                           "![m_sL2 by frame distance](gap_anim_horse.png)");
    /* NN's second pair has a vertex scored by the straight line: said. */
    assert_contains(horse, "- NN: 1 of 10 vertices (10.00 %)");
    assert_null(strstr(horse, "- AN: 0 of"));
    free(horse);
}

static void test_md_failed_method_shows_status(void **state)
{
    fixture *f = *state;
    char *camel = section(f->md, "### anim / camel");
    assert_contains(camel, "| DSR (seed 0) | *failed* | *failed* | *failed* | *failed* | *failed* "
                           "| *failed* |");
    assert_contains(camel, "- DSR: failed — seed 0: loss became NaN at iteration 7");
    free(camel);
}

static void test_md_mean_over_test_sequences_only(void **state)
{
    fixture *f = *state;
    char *mean = section(f->md, "### anim / MEAN");
    const int tests[] = {1, 2}, all[] = {0, 1, 2};
    char row[512];
    expect an = expected_mean(tests, 2, 0), nn = expected_mean(tests, 2, 1);
    /* AN leads on m_sL2 and AUC, rank equal to NN's, but two sequences
     * cannot make a difference significant: AN and NN tied; CD is AN's
     * alone (NN has none, DSR failed), so not marked. */
    md_row("AN", &an, 0, 0x37, 0, row, sizeof row);
    assert_contains(mean, row);
    md_row("NN", &nn, 0, 0x37, 1, row, sizeof row);
    assert_contains(mean, row);
    assert_contains(mean, "Here the test sequences (2) are resampled: so few that the intervals are rough");
    /* The validation sequence must not leak into the mean. */
    expect with_cat = expected_mean(all, 3, 0);
    md_row("AN", &with_cat, 0, 0x37, 0, row, sizeof row);
    assert_null(strstr(mean, row));
    /* A method failed on one test sequence gets no MEAN numbers. */
    assert_contains(mean, "| DSR | *failed* | *failed* | *failed* | *failed* | *failed* | *failed* |");
    assert_contains(mean, "- NN: 2 of 20 vertices (10.00 %)");
    assert_contains(mean, "- DSR: failed (1/2 test sequences) — camel: seed 0: loss became NaN");
    assert_contains(mean, "2 test sequences (camel, horse)");
    free(mean);
    char *ama = section(f->md, "### ama / MEAN");
    assert_contains(ama, "No test sequence");
    assert_null(strstr(ama, "| AN |"));
    free(ama);
}

/* "| 1 | AN | **1.23** | … |": one cell's means, `bold` a 6-bit mask. */
static void md_seed_row(int seed, const char *method, const expect *e, int bold, int no_cd,
                        char *out, size_t size)
{
    size_t used = (size_t)snprintf(out, size, "| %d | %s |", seed, method);
    for (int j = 0; j < N_COLS; j++) {
        const char *b = bold >> j & 1 ? "**" : "";
        if (j == 3 && no_cd)
            used += (size_t)snprintf(out + used, size - used, " - |");
        else
            used += (size_t)snprintf(out + used, size - used, " %s%.*f%s |", b, DECIMALS[j],
                                     e->mean[j], b);
    }
}

static void test_md_per_seed_table(void **state)
{
    fixture *f = *state;
    char *horse = section(f->md, "### anim / horse");
    char row[512];
    assert_contains(horse, "Per seed (each cell's means; best per seed in **bold** by its value alone, untested: "
                           "which differences are real, the table above and comparisons.md say):");
    /* Seed 0: every method, DSR best, rank tied; seed 1: AN alone, with
     * nothing to be better than, so nothing bold. */
    expect an0 = expected_seeds(1, 0, 0, 1), an1 = expected_seeds(1, 0, 1, 1);
    expect nn0 = expected_seeds(1, 1, 0, 1), dsr0 = expected_seeds(1, 2, 0, 1);
    md_seed_row(0, "AN", &an0, 0x2, 0, row, sizeof row);
    assert_contains(horse, row);
    md_seed_row(0, "NN", &nn0, 0x2, 1, row, sizeof row);
    assert_contains(horse, row);
    md_seed_row(0, "DSR", &dsr0, 0x3F, 0, row, sizeof row);
    assert_contains(horse, row);
    md_seed_row(1, "AN", &an1, 0x0, 0, row, sizeof row);
    assert_contains(horse, row);
    /* Seed order: all of seed 0 before seed 1. */
    assert_true(strstr(horse, "| 0 | NN |") < strstr(horse, "| 1 | AN |"));
    free(horse);
    char *camel = section(f->md, "### anim / camel");
    assert_contains(camel, "| 0 | DSR | *failed* | *failed* | *failed* | *failed* | *failed* | *failed* |");
    free(camel);
    char *mean = section(f->md, "### anim / MEAN");
    assert_null(strstr(mean, "Per seed"));
    free(mean);
}

/* ------------------------------------------------------------------ CSV */

#define CSV_MAX_FIELDS 46
typedef struct csv_row {
    char field[CSV_MAX_FIELDS][64];
} csv_row;

/* Plain comma splitting: the fake run's names need no CSV quoting. Every
 * line must have `n_fields` fields. */
static int parse_csv(const char *text, int n_fields, csv_row *rows, int max)
{
    int n = 0;
    for (const char *line = text; *line && n < max; n++) {
        const char *end = strchr(line, '\n'), *p = line;
        int f = 0;
        for (;; f++) {
            const char *stop = p;
            while (stop < end && *stop != ',') stop++;
            if (f < CSV_MAX_FIELDS) snprintf(rows[n].field[f], 64, "%.*s", (int)(stop - p), p);
            if (stop == end) break;
            p = stop + 1;
        }
        assert_int_equal(f + 1, n_fields);
        line = end + 1;
    }
    return n;
}

/* report/<name> parsed, `n_fields` per line; *n gets the line count
 * (header included). The caller frees the rows. */
static csv_row *read_csv(const fixture *f, const char *name, int n_fields, int *n)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", f->report, name);
    char *text = read_all(path);
    csv_row *rows = calloc(64, sizeof *rows);
    *n = parse_csv(text, n_fields, rows, 64);
    free(text);
    return rows;
}

static const csv_row *find_csv(const csv_row *rows, int n, const char *seq, const char *method)
{
    for (int k = 1; k < n; k++)
        if (!strcmp(rows[k].field[1], seq) && !strcmp(rows[k].field[3], method)) return &rows[k];
    fail_msg("no CSV row %s/%s", seq, method);
    return NULL;
}

/* results.csv: the paper's metrics from field 7, sL2² at 15 and 16, the
 * geodesic ones from 17, the fallback count at 21, the marks from 22. */
static void assert_csv_values(const csv_row *r, const expect *e, int has_cd)
{
    for (int j = 0; j < N_COLS; j++) {
        int at = j < 4 ? 7 + 2 * j : 17 + 2 * (j - 4);
        const char *mean = r->field[at], *std = r->field[at + 1];
        if (j == 3 && !has_cd) {
            assert_string_equal(mean, "");
            assert_string_equal(std, "");
            continue;
        }
        double half_ulp = 0.5 * pow(10, -DECIMALS[j]) + 1e-12;
        assert_true(fabs(strtod(mean, NULL) - e->mean[j]) <= half_ulp);
        assert_true(fabs(strtod(std, NULL) - e->std[j]) <= half_ulp);
    }
    assert_int_equal(atoi(r->field[21]), e->unreachable);
}

static void test_csv_parses_back(void **state)
{
    fixture *f = *state;
    int n;
    csv_row *rows = read_csv(f, "results.csv", 46, &n);
    /* header + 4 sequences × 3 methods + anim's 3 MEAN rows */
    assert_int_equal(n, 1 + 12 + 3);
    /* where the columns are: every addition at the end (Corr before the
     * marks, the reconstruction metrics and their marks after them) */
    static const struct { int at; const char *name; } cols[] = {
        {7, "sl2_x1e3_mean"},   {15, "sl2sq_x1e3_mean"},  {17, "geo_x1e3_mean"},   {21, "geo_unreachable"},
        {22, "corr_x1e3_mean"}, {24, "sl2_mark"},         {30, "corr_mark"},       {31, "cdl2_x1e5_mean"},
        {33, "nc_pct_mean"},    {35, "fscore05_pct_mean"}, {37, "fscore1_pct_mean"}, {39, "cdl2_mark"},
        {42, "fscore1_mark"},     {43, "corr_mesh_x1e3_mean"}, {45, "corr_mesh_mark"}};
    for (size_t k = 0; k < sizeof cols / sizeof *cols; k++) assert_string_equal(rows[0].field[cols[k].at], cols[k].name);
    expect an = expected(1, 0), nn = expected(1, 1);
    const csv_row *r = find_csv(rows, n, "horse", "AN");
    assert_string_equal(r->field[2], "test");
    assert_string_equal(r->field[4], "ok");
    assert_string_equal(r->field[5], "2");
    assert_string_equal(r->field[6], "2");
    assert_csv_values(r, &an, 1);
    assert_csv_values(find_csv(rows, n, "horse", "NN"), &nn, 0);
    /* 2 pairs: nothing significant, every row tied for best (NN has no CD) */
    assert_string_equal(r->field[24], "tie");
    assert_string_equal(find_csv(rows, n, "horse", "NN")->field[27], "");
    /* no fake cell has surfaces: empty reconstruction fields */
    for (int k = 31; k < 43; k++) assert_string_equal(r->field[k], "");
    const int tests[] = {1, 2};
    expect mean = expected_mean(tests, 2, 0);
    r = find_csv(rows, n, "MEAN", "AN");
    assert_string_equal(r->field[2], "mean");
    assert_csv_values(r, &mean, 1);
    r = find_csv(rows, n, "camel", "DSR");
    assert_string_equal(r->field[4], "failed");
    assert_string_equal(r->field[7], "");
    free(rows);
}

/* m_sL2 of (sequence, method) over the pairs at frame distance `gap`,
 * seeds pooled, in table units, from the raw per-vertex errors. */
static void expected_gap(int s, int m, int gap, double *mean, double *std, int *n_pairs)
{
    double sl2[8 * FAKE_PAIRS * FAKE_NV];
    int nv = 0;
    *n_pairs = 0;
    for (int seed = 0; seed < METHODS[m].n_seeds; seed++) {
        fake_cell c = cell_of(s, m, seed);
        for (int p = 0; p < FAKE_PAIRS; p++) {
            if (fake_gap(p) != gap) continue;
            ++*n_pairs;
            for (int k = 0; k < FAKE_NV; k++) sl2[nv++] = fake_sl2(&c, p, k);
        }
    }
    fake_mean_std(sl2, nv, mean, std);
    *mean *= 1e3, *std *= 1e3;
}

static const csv_row *find_gap(const csv_row *rows, int n, const char *seq, const char *method,
                               int gap)
{
    for (int k = 1; k < n; k++)
        if (!strcmp(rows[k].field[1], seq) && !strcmp(rows[k].field[3], method) &&
            atoi(rows[k].field[4]) == gap)
            return &rows[k];
    return NULL;
}

static void test_gap_csv_by_frame_distance(void **state)
{
    fixture *f = *state;
    int n;
    csv_row *rows = read_csv(f, "by_gap.csv", 9, &n);
    assert_string_equal(rows[0].field[4], "gap");
    /* 2 distances × (4 sequences × 3 methods − DSR failed on camel); no MEAN rows. */
    assert_int_equal(n, 1 + 2 * (N_SEQS * N_METHODS - 1));
    assert_null(find_gap(rows, n, "camel", "DSR", 1));
    assert_null(find_gap(rows, n, "MEAN", "AN", 1));
    for (int s = 0; s < N_SEQS; s++)
        for (int m = 0; m < N_METHODS; m++)
            for (int gap = 1; gap <= 2; gap++) {
                const csv_row *r = find_gap(rows, n, SEQS[s].name, METHODS[m].name, gap);
                if (!r) continue;
                double mean, std;
                int n_pairs;
                expected_gap(s, m, gap, &mean, &std, &n_pairs);
                assert_string_equal(r->field[2], SEQS[s].role);
                assert_int_equal(atoi(r->field[5]), n_pairs);
                assert_int_equal(atoi(r->field[6]), n_pairs * FAKE_NV);
                assert_true(fabs(strtod(r->field[7], NULL) - mean) <= 0.005 + 1e-12);
                assert_true(fabs(strtod(r->field[8], NULL) - std) <= 0.005 + 1e-12);
            }
    /* Two seeds of AN pooled: both pairs at distance 2. */
    assert_string_equal(find_gap(rows, n, "horse", "AN", 2)->field[5], "2");
    free(rows);
}

static void test_seed_csv_one_row_per_cell(void **state)
{
    fixture *f = *state;
    int n;
    csv_row *rows = read_csv(f, "seeds.csv", 19, &n);
    assert_string_equal(rows[0].field[14], "cdl2_x1e5_mean");
    assert_string_equal(rows[0].field[17], "fscore1_pct_mean");
    assert_string_equal(rows[0].field[18], "corr_mesh_x1e3_mean");
    assert_string_equal(rows[0].field[4], "seed");
    int n_cells = 0;
    for (int m = 0; m < N_METHODS; m++) n_cells += N_SEQS * METHODS[m].n_seeds;
    assert_int_equal(n, 1 + n_cells);
    for (int s = 0; s < N_SEQS; s++)
        for (int m = 0; m < N_METHODS; m++)
            for (int seed = 0; seed < METHODS[m].n_seeds; seed++) {
                const csv_row *r = NULL;
                for (int k = 1; k < n && !r; k++)
                    if (!strcmp(rows[k].field[1], SEQS[s].name) &&
                        !strcmp(rows[k].field[3], METHODS[m].name) && atoi(rows[k].field[4]) == seed)
                        r = &rows[k];
                assert_non_null(r);
                assert_string_equal(r->field[2], SEQS[s].role);
                fake_cell c = cell_of(s, m, seed);
                /* A failed cell scored no pairs. */
                assert_int_equal(atoi(r->field[6]), c.status == TCB_CELL_OK ? FAKE_PAIRS : 0);
                if (c.status != TCB_CELL_OK) {
                    assert_string_equal(r->field[5], "failed");
                    for (int j = 0; j < N_COLS; j++) assert_string_equal(r->field[7 + j], "");
                    continue;
                }
                assert_string_equal(r->field[5], "ok");
                expect e = expected_seeds(s, m, seed, 1);
                for (int j = 0; j < N_COLS; j++) {
                    if (j == 3 && !METHODS[m].has_cd) {
                        assert_string_equal(r->field[7 + j], "");
                        continue;
                    }
                    double half_ulp = 0.5 * pow(10, -DECIMALS[j]) + 1e-12;
                    assert_true(fabs(strtod(r->field[7 + j], NULL) - e.mean[j]) <= half_ulp);
                }
            }
    free(rows);
}

/* ----------------------------------------------------------- TeX, PNG */

static void test_tex_uses_booktabs(void **state)
{
    fixture *f = *state;
    char path[4096];
    snprintf(path, sizeof path, "%s/tables.tex", f->report);
    char *tex = read_all(path);
    assert_contains(tex, "\\toprule");
    assert_contains(tex, "\\midrule");
    assert_contains(tex, "\\bottomrule");
    assert_contains(tex, "m\\_sL2 $\\downarrow$");
    /* no cell scored clips or has surfaces: no Corr, Corr-mesh, CD-L2, NC, F columns */
    assert_contains(tex, "m\\_geo $\\downarrow$ & AUC\\_geo $\\uparrow$ \\\\");
    assert_contains(tex, "\\begin{tabular}{llcccccc}");
    /* DSR leads, tied for best (2 pairs: nothing can be significant) */
    expect dsr = expected(1, 2);
    char tied[128];
    snprintf(tied, sizeof tied, " & %.2f $\\pm$ %.2f$^{\\approx}$ &", dsr.mean[0], dsr.std[0]);
    assert_contains(tex, tied);
    assert_null(strstr(tex, "\\textbf{"));
    free(tex);
}

static unsigned be32(const unsigned char *p)
{
    return (unsigned)p[0] << 24 | (unsigned)p[1] << 16 | (unsigned)p[2] << 8 | p[3];
}

static void test_pngs_are_valid(void **state)
{
    fixture *f = *state;
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static const char *const kinds[] = {"pck", "pck_geo", "gap"};
    for (int s = 0; s < 3 * N_SEQS; s++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s_%s_%s.png", f->report, kinds[s / N_SEQS],
                 SEQS[s % N_SEQS].dataset, SEQS[s % N_SEQS].name);
        FILE *fp = fopen(path, "rb");
        assert_non_null(fp);
        unsigned char head[24];
        assert_int_equal(fread(head, 1, sizeof head, fp), sizeof head);
        fclose(fp);
        assert_memory_equal(head, sig, 8);
        assert_memory_equal(head + 12, "IHDR", 4);
        assert_int_equal(be32(head + 16), 900);
        assert_int_equal(be32(head + 20), 600);
    }
    /* Nothing but the published outputs: no temporaries left behind. */
    DIR *d = opendir(f->report);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) {
        if (e->d_name[0] == '.') continue;
        assert_null(strstr(e->d_name, ".tmp-"));
        n++;
    }
    closedir(d);
    assert_int_equal(n, 8 + 3 * N_SEQS);
}

/* The Markdown row of `method` in md (up to its line's end). */
static char *md_line(const char *md, const char *method)
{
    char head[96];
    snprintf(head, sizeof head, "\n| %s |", method);
    const char *at = strstr(md, head);
    assert_non_null(at);
    size_t from = (size_t)(at - md) + 1, len = strcspn(md + from, "\n");
    char *line = malloc(len + 1);
    memcpy(line, md + from, len);
    line[len] = '\0';
    return line;
}

static int ends_with(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    return n >= m && !strcmp(s + n - m, tail);
}

/* Cells written before the geodesic error: "-" in its columns, the
 * paper's numbers as before; a method pooling an old and a new seed has
 * no geodesic numbers either (not a part passed off as the whole). */
static void test_old_cells_show_dash(void **state)
{
    (void)state;
    char dir[512];
    tu_make_tmpdir(dir, sizeof dir);
    const fake_cell cells[] = {
        {"anim", "horse", "test", "OLD", 0, TCB_CELL_OK, 0.01, 1, 1},
        {"anim", "horse", "test", "NEW", 0, TCB_CELL_OK, 0.02, 1, 0},
        {"anim", "horse", "test", "MIX", 0, TCB_CELL_OK, 0.03, 1, 0},
        {"anim", "horse", "test", "MIX", 1, TCB_CELL_OK, 0.03, 1, 1},
    };
    for (int k = 0; k < 4; k++) assert_int_equal(fake_write(dir, &cells[k]), 0);
    tcb_error err = {0};
    assert_int_equal(tcb_report_write(dir, NULL, NULL, &err), TCB_OK);
    char path[4096];
    snprintf(path, sizeof path, "%s/report/tables.md", dir);
    char *md = read_all(path);
    /* (OLD and NEW ran one of the block's two seeds, which their rows say) */
    char *old = md_line(md, "OLD (seed 0)"), *neu = md_line(md, "NEW (seed 0)"), *mix = md_line(md, "MIX");
    /* OLD: leads on the paper's m_sL2 (tied for best: 2 pairs cannot make it
     * significant), "-" for the geodesic error */
    /* (no Corr or reconstruction columns: no cell has clips or surfaces;
     * the geodesic error's two last) */
    const char *none2 = "| - | - |";
    if (strncmp(old, "| OLD (seed 0) | ", 17) || !strstr(old, " ≈ |") || !ends_with(old, none2)) fail_msg("%s", old);
    if (!ends_with(mix, none2)) fail_msg("%s", mix);
    if (strstr(md, "Corr ↓") || strstr(md, "CD-L2 ↓")) fail_msg("columns no cell has are shown");
    /* NEW alone has geodesic numbers, with nothing to compare: not marked */
    if (ends_with(neu, " - |") || strstr(neu, "**") || strstr(neu, "≈ | - |")) fail_msg("%s", neu);
    snprintf(path, sizeof path, "%s/report/pck_geo_anim_horse.png", dir);
    assert_true(tcb_is_file(path));
    free(old), free(neu), free(mix), free(md);
    tu_remove_tree(dir);
}

static void set_impl(cJSON *root, const void *impl)
{
    cJSON_ReplaceItemInObject(root, "method_impl", cJSON_CreateString(impl));
}

/* atlasnet and mca cells of the same params, m_sL2 `gap` apart (relative):
 * tables.md's text. */
static char *twins_md(double gap)
{
    char dir[512], path[4096];
    tu_make_tmpdir(dir, sizeof dir);
    const fake_cell a = {"anim", "horse", "test", "AN", 0, TCB_CELL_OK, 0.1, 1, 0},
                    m = {"anim", "horse", "test", "MCA", 0, TCB_CELL_OK, 0.1 * (1 + gap), 1, 0};
    assert_int_equal(fake_write(dir, &a) || fake_write(dir, &m), 0);
    assert_int_equal(fake_edit(dir, &a, set_impl, "atlasnet") || fake_edit(dir, &m, set_impl, "mca"), 0);
    tcb_error err = {0};
    if (tcb_report_write(dir, NULL, NULL, &err)) fail_msg("%s", err.msg);
    snprintf(path, sizeof path, "%s/report/tables.md", dir);
    char *md = read_all(path);
    tu_remove_tree(dir);
    return md;
}

/* atlasnet and mca 0.5 % apart: the notes under the sequence's table and
 * the MEAN's say why; 3 % apart: nothing to explain. */
static void test_atlasnet_mca_agreement_explained(void **state)
{
    (void)state;
    char *md = twins_md(0.005);
    const char *note = "AN and MCA agree on m_sL2 (", *why = "differ only by mca's metric-consistency term";
    const char *first = strstr(md, note);
    if (!first || !strstr(first + 1, note) || !strstr(md, why)) fail_msg("no note twice in:\n%s", md);
    free(md);
    md = twins_md(0.03);
    if (strstr(md, note)) fail_msg("a note for rows 3 %% apart:\n%s", md);
    free(md);
}

static void test_empty_run_is_an_error(void **state)
{
    (void)state;
    char dir[512], cells[4096];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_error err = {0};
    assert_int_equal(tcb_report_write(dir, NULL, NULL, &err), TCB_ERR_IO);
    snprintf(cells, sizeof cells, "%s/cells", dir);
    assert_int_equal(tcb_mkdirs(cells, &err), TCB_OK);
    assert_int_equal(tcb_report_write(dir, NULL, NULL, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "no cell files"));
    tu_remove_tree(dir);
}

/* Fontconfig, which cairo uses to find fonts, keeps its configuration until
 * FcFini, which nothing calls at exit: not a leak of ours. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libfontconfig.so\n"; }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_md_sequence_block_bold_and_dash),
        cmocka_unit_test(test_md_failed_method_shows_status),
        cmocka_unit_test(test_md_mean_over_test_sequences_only),
        cmocka_unit_test(test_md_per_seed_table),
        cmocka_unit_test(test_csv_parses_back),
        cmocka_unit_test(test_gap_csv_by_frame_distance),
        cmocka_unit_test(test_seed_csv_one_row_per_cell),
        cmocka_unit_test(test_tex_uses_booktabs),
        cmocka_unit_test(test_pngs_are_valid),
    };
    const struct CMUnitTest standalone[] = {cmocka_unit_test(test_empty_run_is_an_error),
                                            cmocka_unit_test(test_old_cells_show_dash),
                                            cmocka_unit_test(test_atlasnet_mca_agreement_explained)};
    int failed = cmocka_run_group_tests(tests, setup, teardown);
    return failed + cmocka_run_group_tests(standalone, NULL, NULL);
}

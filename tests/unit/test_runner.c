/* The grid runner through its API: cells, stats, progress labels, resume,
 * --only/--force, the errors that abort a run before any cell, failed
 * cells (counted, listed, retried) and a run directory that grows with its
 * config. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"
#include "tcb/config.h"
#include "tcb/fsutil.h"
#include "tcb/results.h"
#include "tcb/runner.h"

typedef struct progress_log {
    int calls;
    int finished_cells; /* progress calls with done == total > 0 on a cell label */
    char last_label[256];
} progress_log;

static void on_progress(void *ctx, double done, double total, const char *label)
{
    progress_log *p = ctx;
    p->calls++;
    snprintf(p->last_label, sizeof p->last_label, "%s", label);
    if (done == total && total > 0 && strstr(label, "/seed ")) p->finished_cells++;
}

/* A config in `dir`: synthetic quadruped_walk, 8 frames, 5 pairs, seeds
 * 0 and 1; `methods` and `extra_dataset` are spliced in. */
static void parse_config(const char *dir, const char *methods, const char *extra_dataset,
                         tcb_config *c)
{
    char text[4096];
    snprintf(text, sizeof text,
             "{\"name\": \"unit\", \"output\": \"%s/run\", \"splits_dir\": \"%s/splits\",\n"
             " \"cache_dir\": \"\", \"seeds\": [0, 1],\n"
             " \"evaluation\": {\"pairs\": 5, \"pool_size\": 500},\n"
             " \"datasets\": [{\"name\": \"synth\", \"source\": \"synthetic\", \"frames\": 8,\n"
             "   \"sequences\": [{\"name\": \"quadruped_walk\", \"role\": \"test\"}]}%s],\n"
             " \"methods\": [%s]}",
             dir, dir, extra_dataset, methods);
    tcb_error err = {0};
    if (tcb_config_parse(text, "unit.json", c, &err)) fail_msg("%s", err.msg);
}

static void test_grid_and_resume(void **state)
{
    (void)state;
    char dir[512], path[1024];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_config c;
    /* nearest runs its own seeds instead of the config's 0 and 1. */
    parse_config(dir, "{\"name\": \"oracle\"}, {\"name\": \"nearest\", \"seeds\": [1, 5]}", "",
                 &c);
    progress_log log = {0};
    tcb_run_opts opts = {.reporter = {on_progress, NULL, &log}};
    tcb_run_stats st;
    tcb_error err = {0};

    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_OK);
    assert_null(st.failures);
    assert_int_equal(st.cells_total, 4);
    assert_int_equal(st.cells_done, 4);
    assert_int_equal(st.cells_skipped, 0);
    assert_int_equal(st.cells_failed, 0);
    assert_int_equal(log.finished_cells, 4);
    assert_string_equal(log.last_label, "synth/quadruped_walk/nearest/seed 5");
    snprintf(path, sizeof path, "%s/run/cells/synth/quadruped_walk/oracle/seed_1.json", dir);
    assert_true(tcb_is_file(path));
    snprintf(path, sizeof path, "%s/run/cells/synth/quadruped_walk/nearest/seed_0.json", dir);
    assert_false(tcb_is_file(path));
    snprintf(path, sizeof path, "%s/run/work/synth/quadruped_walk/nearest/seed_5", dir);
    assert_true(tcb_is_dir(path));

    /* config.json is the normalized config. */
    char *saved;
    snprintf(path, sizeof path, "%s/run/config.json", dir);
    assert_int_equal(tcb_read_file(path, &saved, NULL, &err), TCB_OK);
    assert_int_equal(strncmp(saved, c.json_text, strlen(c.json_text)), 0);
    free(saved);

    /* Rerun: every cell is skipped, no progress for finished cells. */
    log = (progress_log){0};
    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_OK);
    assert_int_equal(st.cells_skipped, 4);
    assert_int_equal(st.cells_done, 0);
    assert_int_equal(log.finished_cells, 0);

    /* --only + --force recomputes just that method. */
    opts.only_method = "nearest";
    opts.force = 1;
    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_OK);
    assert_int_equal(st.cells_total, 2);
    assert_int_equal(st.cells_done, 2);

    /* --output overrides the config's directory. */
    char other[600];
    snprintf(other, sizeof other, "%s/other", dir);
    opts = (tcb_run_opts){.output = other, .only_method = "oracle"};
    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_OK);
    snprintf(path, sizeof path, "%s/cells/synth/quadruped_walk/oracle/seed_0.json", other);
    assert_true(tcb_is_file(path));
    tcb_config_free(&c);
    tu_remove_tree(dir);
}

static void test_errors_before_any_cell(void **state)
{
    (void)state;
    char dir[512], path[1024];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_run_opts opts = {0};
    tcb_run_stats st;
    tcb_error err = {0};
    tcb_config c;

    parse_config(dir, "{\"name\": \"oracle\"}, {\"name\": \"nope\"}", "", &c);
    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "unit.json: methods[1]: no method named 'nope'"));
    tcb_config_free(&c);

    parse_config(dir, "{\"name\": \"nearest\", \"params\": {\"bogus\": 1}}", "", &c);
    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "unit.json: methods[0].params: "));
    tcb_config_free(&c);

    parse_config(dir, "{\"name\": \"oracle\"}", "", &c);
    opts.only_method = "nearest";
    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "--only: unit.json has no method labelled 'nearest'"));
    tcb_config_free(&c);
    opts.only_method = NULL;

    /* A required objdir root that is absent: an I/O error naming it. */
    parse_config(dir, "{\"name\": \"oracle\"}",
                 ", {\"name\": \"real\", \"source\": \"objdir\", \"root\": \"/nonexistent/tcb\","
                 " \"sequences\": [{\"name\": \"cat\", \"role\": \"test\"}]}",
                 &c);
    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_ERR_IO);
    assert_non_null(strstr(err.msg, "datasets[1].root: /nonexistent/tcb: no such directory"));
    tcb_config_free(&c);

    snprintf(path, sizeof path, "%s/run", dir);
    assert_false(tcb_is_dir(path)); /* each error came before the run directory */
    tu_remove_tree(dir);
}

/* Rewrites the cell file of `method`, seed 0, with `status`. */
static void set_status(const char *dir, const char *method, tcb_cell_status status)
{
    char path[1024];
    tcb_cell_result cell;
    tcb_error err = {0};
    snprintf(path, sizeof path, "%s/run/cells/synth/quadruped_walk/%s/seed_0.json", dir, method);
    if (tcb_cell_load(path, &cell, &err)) fail_msg("%s", err.msg);
    cell.status = status;
    snprintf(cell.message, sizeof cell.message, "set by the test");
    if (tcb_cell_save(path, &cell, &err)) fail_msg("%s", err.msg);
    tcb_cell_free(&cell);
}

/* A cell whose method fails is written, counted and listed, and the run
 * goes on; a rerun computes a failed cell again and keeps a diverged one
 * (a diverged training is the method's result). */
static void test_failed_cells(void **state)
{
    (void)state;
    char dir[512];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_config c;
    parse_config(dir,
                 "{\"name\": \"oracle\"}, {\"name\": \"nearest\"},"
                 " {\"name\": \"broken\", \"method\": \"external\", \"params\": {\"command\": [\"/nonexistent/tcb\"]},"
                 "  \"seeds\": [0]}",
                 "", &c);
    tcb_run_opts opts = {0};
    tcb_run_stats st;
    tcb_error err = {0};
    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_OK);
    assert_int_equal(st.cells_done, 5);
    assert_int_equal(st.cells_failed, 1);
    assert_int_equal(st.cells_diverged, 0);
    assert_non_null(st.failures);
    assert_non_null(strstr(st.failures, "synth/quadruped_walk/broken/seed 0: fit: external.params.command: "
                                        "'/nonexistent/tcb': no such executable file\n"));
    tcb_run_stats_free(&st);

    /* Rerun: the failed cell again (it fails again), the others kept. */
    set_status(dir, "oracle", TCB_CELL_DIVERGED);
    set_status(dir, "nearest", TCB_CELL_FAILED);
    assert_int_equal(tcb_run(&c, &opts, &st, &err), TCB_OK);
    assert_int_equal(st.cells_total, 5);
    assert_int_equal(st.cells_skipped, 3);
    assert_int_equal(st.cells_done, 2);
    assert_int_equal(st.cells_failed, 1);
    tcb_run_stats_free(&st);
    char path[1024];
    tcb_cell_result cell;
    snprintf(path, sizeof path, "%s/run/cells/synth/quadruped_walk/nearest/seed_0.json", dir);
    assert_int_equal(tcb_cell_load(path, &cell, &err), TCB_OK);
    assert_int_equal(cell.status, TCB_CELL_OK);
    tcb_cell_free(&cell);
    snprintf(path, sizeof path, "%s/run/cells/synth/quadruped_walk/oracle/seed_0.json", dir);
    assert_int_equal(tcb_cell_load(path, &cell, &err), TCB_OK);
    assert_int_equal(cell.status, TCB_CELL_DIVERGED);
    tcb_cell_free(&cell);
    tcb_config_free(&c);
    tu_remove_tree(dir);
}

/* Runs a config of `methods` on the run directory in `dir`: the rc. */
static int run_grown(const char *dir, const char *methods, const char *extra_dataset, tcb_run_stats *st,
                     tcb_error *err)
{
    tcb_config c;
    parse_config(dir, methods, extra_dataset, &c);
    tcb_run_opts opts = {0};
    int rc = tcb_run(&c, &opts, st, err);
    tcb_run_stats_free(st);
    tcb_config_free(&c);
    return rc;
}

/* Added methods, seeds and datasets run with no flag; a method whose
 * params changed is refused alone (key path, both values), the others
 * run; the record is the union of the configs; a changed evaluation or
 * dataset setting refuses the whole run. */
static void test_grown_config(void **state)
{
    (void)state;
    char dir[512], path[1024];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_run_stats st;
    tcb_error err = {0};
    assert_int_equal(run_grown(dir, "{\"name\": \"oracle\"}", "", &st, &err), TCB_OK);
    assert_int_equal(run_grown(dir, "{\"name\": \"nearest\", \"seeds\": [0, 7]}", "", &st, &err), TCB_OK);
    assert_int_equal(st.cells_done, 2);
    const char *synth2 = ", {\"name\": \"synth2\", \"source\": \"synthetic\", \"frames\": 6,"
                         " \"sequences\": [{\"name\": \"quadruped_trot\", \"role\": \"test\"}]}";
    assert_int_equal(run_grown(dir, "{\"name\": \"oracle\"}, {\"name\": \"nricp\", \"params\": {\"rounds\": 1}}",
                               synth2, &st, &err),
                     TCB_OK);
    assert_int_equal(st.cells_skipped, 2);
    assert_int_equal(st.cells_done, 6);

    /* nricp's rounds changed: it is refused, nearest's new seed runs. */
    int rc = run_grown(dir,
                       "{\"name\": \"nricp\", \"params\": {\"rounds\": 2}}, {\"name\": \"nearest\", \"seeds\": [3]}",
                       "", &st, &err);
    assert_int_equal(rc, TCB_ERR_INPUT);
    assert_int_equal(st.refused, 1);
    assert_int_equal(st.cells_total, 1);
    assert_int_equal(st.cells_done, 1);
    assert_non_null(strstr(err.msg, "(methods[nricp].params.rounds: 1 there, 2 here)"));
    assert_non_null(strstr(err.msg, "'tcbench run unit.json --force --only nricp'"));
    snprintf(path, sizeof path, "%s/run/cells/synth/quadruped_walk/nearest/seed_3.json", dir);
    assert_true(tcb_is_file(path));

    /* The record: every method, dataset and seed of the four configs; nricp as it ran. */
    tcb_config rec;
    snprintf(path, sizeof path, "%s/run/config.json", dir);
    assert_int_equal(tcb_config_load(path, &rec, &err), TCB_OK);
    assert_int_equal(rec.n_methods, 3);
    assert_int_equal(rec.n_datasets, 2);
    assert_int_equal(tcb_grid_count(&rec), 2 * (2 + 3 + 2)); /* oracle 0 1; nearest 3 0 7; nricp 0 1 */
    assert_string_equal(rec.methods[0].label, "nricp");
    assert_string_equal(rec.methods[0].params_json, "{\"rounds\":1}");
    tcb_config_free(&rec);

    /* A setting every cell depends on: the whole run is refused, nothing runs. */
    rc = run_grown(dir, "{\"name\": \"oracle\"}",
                   ", {\"name\": \"synth2\", \"source\": \"synthetic\", \"frames\": 7,"
                   " \"sequences\": [{\"name\": \"quadruped_trot\", \"role\": \"test\"}]}",
                   &st, &err);
    assert_int_equal(rc, TCB_ERR_INPUT);
    assert_int_equal(st.cells_total, 0);
    assert_non_null(strstr(err.msg, "(datasets[synth2].frames: 6 there, 7 here)"));
    tu_remove_tree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grid_and_resume),
        cmocka_unit_test(test_errors_before_any_cell),
        cmocka_unit_test(test_failed_cells),
        cmocka_unit_test(test_grown_config),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

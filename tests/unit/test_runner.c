/* The grid runner through its API: cells, stats, progress labels, resume,
 * --only/--force, and the errors that abort a run before any cell. */
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grid_and_resume),
        cmocka_unit_test(test_errors_before_any_cell),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

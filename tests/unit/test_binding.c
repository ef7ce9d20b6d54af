/* The flat entry points for bindings (tcb/binding.h) and what they stand
 * on: pair metrics equal to the row tcb_cell_score_pair records, a split
 * as its file's JSON, a config's sequence as `tcbench run` loads it
 * (tcb_run_load_sequence), its arrays described and copied with their
 * sizes checked, and the C messages for every failure. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scoring/scoring.h"
#include "store/cell_format.h"
#include "testutil.h"
#include "tcb/binding.h"
#include "tcb/json.h"
#include "tcb/runner.h"
#include "tcb/rng.h"
#include "tcb/synth.h"

static cJSON *parsed(char *text)
{
    assert_non_null(text);
    cJSON *j = cJSON_Parse(text);
    tcb_binding_free(text);
    assert_non_null(j);
    return j;
}

static void expect_message(int rc, const tcb_error *err, int code, const char *text)
{
    assert_int_equal(rc, code);
    if (!strstr(err->msg, text)) fail_msg("'%s' does not say '%s'", err->msg, text);
}

static void test_info(void **state)
{
    (void)state;
    cJSON *info = parsed(tcb_binding_info());
    assert_int_equal(cJSON_GetObjectItem(info, "pck_steps")->valueint, TCB_PCK_STEPS);
    const cJSON *cols = cJSON_GetObjectItem(info, "pair_columns"), *e = cJSON_GetObjectItem(info, "tcb_error");
    assert_int_equal(cJSON_GetArraySize(cols), TCB_N_PAIR_COLUMNS);
    for (int k = 0; k < TCB_N_PAIR_COLUMNS; k++)
        assert_string_equal(cJSON_GetArrayItem(cols, k)->valuestring, tcb_cell_pair_columns[k]);
    assert_int_equal(cJSON_GetObjectItem(e, "size")->valueint, sizeof(tcb_error));
    assert_int_equal(cJSON_GetObjectItem(e, "msg_offset")->valueint, offsetof(tcb_error, msg));
    assert_int_equal(cJSON_GetObjectItem(e, "msg_size")->valueint, TCB_ERRMSG_MAX);
    cJSON_Delete(info);
}

/* The row equals the record a cell gets for the same prediction, bit for
 * bit (the frames and the Chamfer distance left NaN, and the geodesic
 * error, which needs faces: neither the binding nor a cell of points
 * without faces has one); sq, rank and pck are the values behind it. */
static void test_pair_metrics_is_the_cells_row(void **state)
{
    (void)state;
    enum { K = 700 };
    tcb_rng rng;
    tcb_rng_seed(&rng, 5);
    float *v = tu_falloc(3 * K);
    tu_fill_uniform(&rng, v, 3 * K, -1, 1);
    int32_t pred[K];
    for (int k = 0; k < K; k++) pred[k] = k % 3 ? k : (int32_t)tcb_rng_below(&rng, K);
    double sq[K], rank[K], pck[TCB_PCK_STEPS], row[TCB_N_PAIR_COLUMNS];
    tcb_error err = {0};
    assert_int_equal(tcb_binding_pair_metrics(v, K, pred, sq, rank, pck, TCB_PCK_STEPS, row, TCB_N_PAIR_COLUMNS,
                                              &err), TCB_OK);

    /* a frame of points without faces: no geodesic error, in the cell as in
     * the binding (not the straight line passed off as a path) */
    double area = 1.0;
    tcb_sequence one = {.n_frames = 1, .n_verts = K, .verts = v, .areas = &area};
    tcb_pair_prediction p = {4, 0, NULL, pred, NAN, NULL};
    tcb_pair_record rec;
    tcb_summary sum;
    tcb_pair_metrics m;
    tcb_pair_scorer scorer;
    tcb_summary_init(&sum);
    assert_int_equal(tcb_pair_scorer_init(&scorer, &one, &err), TCB_OK);
    assert_int_equal(tcb_cell_score_pair(&scorer, &p, &rec, &sum, &m, &err), TCB_OK);
    tcb_pair_scorer_free(&scorer);
    double want[TCB_N_PAIR_COLUMNS];
    tcb_pair_record_row(&rec, want);
    enum { CD = TCB_N_PAIR_COLUMNS_EUCLIDEAN - 1 };
    assert_true(isnan(row[0]) && isnan(row[1]) && isnan(row[CD]) && isnan(want[CD]));
    assert_memory_equal(row + 2, want + 2, (CD - 2) * sizeof *row);
    for (int c = CD + 1; c < TCB_N_PAIR_COLUMNS; c++) assert_true(isnan(row[c]) && isnan(want[c]));
    assert_true(sum.geo.n == 0 && sum.geo_auc.n == 0);
    assert_memory_equal(pck, m.pck, sizeof pck);

    double sq_want[K], rank_want[K];
    assert_int_equal(tcb_pair_vertex_metrics(v, K, pred, sq_want, rank_want, &err), TCB_OK);
    assert_memory_equal(sq, sq_want, sizeof sq);
    assert_memory_equal(rank, rank_want, sizeof rank);
    assert_true(row[3] > 0 && row[9] < 1); /* the fixture has errors */
    free(v);
}

static void test_pair_metrics_errors(void **state)
{
    (void)state;
    const float v[] = {0, 0, 0, 1, 0, 0};
    const int32_t ok[] = {1, 0}, bad[] = {0, -1};
    double sq[2], rank[2], pck[TCB_PCK_STEPS], row[TCB_N_PAIR_COLUMNS];
    tcb_error err = {0};
    int rc = tcb_binding_pair_metrics(v, 2, ok, sq, rank, pck, TCB_PCK_STEPS, row, 11 + TCB_N_PAIR_COLUMNS, &err);
    expect_message(rc, &err, TCB_ERR_INPUT, "the binding expects 100 PCK steps and");
    rc = tcb_binding_pair_metrics(v, 2, bad, sq, rank, pck, TCB_PCK_STEPS, row, TCB_N_PAIR_COLUMNS, &err);
    expect_message(rc, &err, TCB_ERR_INPUT, "metrics: pred[1] = -1 outside [0, 2)");
}

/* The split's JSON is its file's, and a bad file is the reader's error. */
static void test_split_json(void **state)
{
    const char *dir = *state;
    tcb_split s;
    tcb_error err = {0};
    const tcb_block blocks[] = {{"a", 0, 4}, {"b", 4, 6}};
    assert_int_equal(tcb_split_make("d", "q", TCB_ROLE_VALIDATION, 10, blocks, 2, 30, 7, &s, &err), TCB_OK);
    char path[4096], bad[4096];
    snprintf(path, sizeof path, "%s/split.json", dir);
    assert_int_equal(tcb_split_save(path, &s, &err), TCB_OK);
    cJSON *file, *text = parsed(tcb_binding_split_json(path, &err));
    assert_int_equal(tcb_json_load(path, &file, &err), TCB_OK);
    assert_true(cJSON_Compare(file, text, 1));
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(text, "pairs")), 30);
    cJSON_Delete(file);
    cJSON_Delete(text);
    tcb_split_free(&s);

    tu_write_text(dir, "bad.json", "{\"format\": \"tcbench-split/2\"}", bad, sizeof bad);
    assert_null(tcb_binding_split_json(bad, &err));
    expect_message(err.code, &err, TCB_ERR_INPUT, "bad.json.format: expected \"tcbench-split/1\"");
    assert_null(tcb_binding_split_json("/nowhere/split.json", &err));
    assert_int_equal(err.code, TCB_ERR_IO);
}

/* config.json in dir: the synthetic quadruped_walk (8 frames, pool 300)
 * and an OBJ directory of it without a root. */
static void write_config(const char *dir, char *path, size_t size)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"name\": \"b\", \"output\": \"%s/run\", \"splits_dir\": \"%s/splits\", \"cache_dir\": \"\",\n"
             " \"evaluation\": {\"pairs\": 5, \"pool_size\": 300, \"pool_seed\": 4, \"input_points\": 100},\n"
             " \"datasets\": [{\"name\": \"synth\", \"source\": \"synthetic\", \"frames\": 8,\n"
             "   \"sequences\": [{\"name\": \"quadruped_walk\", \"role\": \"test\"}]},\n"
             "  {\"name\": \"files\", \"source\": \"objdir\", \"normalization\": \"none\",\n"
             "   \"sampling\": \"with_replacement\",\n"
             "   \"sequences\": [{\"name\": \"quadruped_walk\", \"role\": \"test\"}]}],\n"
             " \"methods\": [{\"name\": \"oracle\"}]}",
             dir, dir);
    tu_write_text(dir, "config.json", text, path, size);
}

/* The runner's sequence is the generator's, prepared with the config's
 * settings. */
static void test_run_load_sequence(void **state)
{
    const char *dir = *state;
    char path[4096];
    write_config(dir, path, sizeof path);
    tcb_config cfg;
    tcb_sequence got, want;
    tcb_error err = {0};
    assert_int_equal(tcb_config_load(path, &cfg, &err), TCB_OK);
    assert_int_equal(tcb_run_load_sequence(&cfg, "synth", "quadruped_walk", &got, &err), TCB_OK);
    tcb_load_opts o = {TCB_NORM_FIRST_FRAME, 300, 4, NULL, 0, NULL};
    assert_int_equal(tcb_synth_generate("quadruped_walk", 0, 8, &want, &err), TCB_OK);
    assert_int_equal(tcb_sequence_prepare(&want, &o, &err), TCB_OK);
    assert_int_equal(got.n_frames, 8);
    assert_memory_equal(got.verts, want.verts, (size_t)8 * want.n_verts * 3 * sizeof(float));
    assert_memory_equal(got.pools, want.pools, (size_t)8 * 300 * 3 * sizeof(float));
    assert_int_equal(got.input_points, 100);
    assert_int_equal(got.draw_with_replacement, 0);
    tcb_sequence_free(&got);
    tcb_sequence_free(&want);

    int rc = tcb_run_load_sequence(&cfg, "nope", "quadruped_walk", &got, &err);
    expect_message(rc, &err, TCB_ERR_INPUT, "config.json has no dataset named 'nope'");
    rc = tcb_run_load_sequence(&cfg, "synth", "nope", &got, &err);
    expect_message(rc, &err, TCB_ERR_INPUT, "dataset synth of");
    expect_message(rc, &err, TCB_ERR_INPUT, "has no sequence named 'nope'");
    rc = tcb_run_load_sequence(&cfg, "files", "quadruped_walk", &got, &err);
    expect_message(rc, &err, TCB_ERR_INPUT, "config.json: dataset files: no root given (--root files=DIR or "
                                            "TCBENCH_ROOT_FILES)");
    tcb_config_free(&cfg);
}

/* The sequence through the binding: root given as --root gives it, the
 * arrays the JSON lists copy out whole, sizes and names checked. */
static void test_binding_sequence(void **state)
{
    const char *dir = *state;
    char path[4096], objs[2048], sub[4096];
    write_config(dir, path, sizeof path);
    tcb_sequence raw;
    tcb_error err = {0};
    assert_int_equal(tcb_synth_generate("quadruped_walk", 0, 8, &raw, &err), TCB_OK);
    snprintf(objs, sizeof objs, "%s/objs", dir);
    snprintf(sub, sizeof sub, "%s/quadruped_walk", objs);
    assert_int_equal(tcb_sequence_write_objdir(&raw, sub, &err), TCB_OK);

    assert_null(tcb_binding_sequence_load(path, "files", "quadruped_walk", NULL, &err));
    tcb_sequence *s = tcb_binding_sequence_load(path, "files", "quadruped_walk", objs, &err);
    if (!s) fail_msg("%s", err.msg);
    cJSON *j = parsed(tcb_binding_sequence_json(s, &err));
    assert_string_equal(cJSON_GetObjectItem(j, "sampling")->valuestring, "with_replacement");
    assert_string_equal(cJSON_GetObjectItem(j, "normalization")->valuestring, "none");
    const cJSON *verts = cJSON_GetObjectItem(cJSON_GetObjectItem(j, "arrays"), "verts");
    assert_string_equal(cJSON_GetObjectItem(verts, "dtype")->valuestring, "float32");
    const cJSON *shape = cJSON_GetObjectItem(verts, "shape");
    assert_int_equal(cJSON_GetArrayItem(shape, 1)->valueint, raw.n_verts);
    cJSON_Delete(j);

    size_t bytes = (size_t)8 * raw.n_verts * 3 * sizeof(float);
    float *copy = tu_falloc(bytes / sizeof(float));
    assert_int_equal(tcb_binding_sequence_copy(s, "verts", copy, bytes, &err), TCB_OK);
    assert_memory_equal(copy, raw.verts, bytes);
    expect_message(tcb_binding_sequence_copy(s, "verts", copy, bytes - 4, &err), &err, TCB_ERR_INPUT,
                   "array verts has");
    expect_message(tcb_binding_sequence_copy(s, "yaw", copy, 8 * sizeof(double), &err), &err, TCB_ERR_INPUT,
                   "has no array named 'yaw'");
    double scale;
    assert_int_equal(tcb_binding_sequence_copy(s, "norm_scale", &scale, sizeof scale, &err), TCB_OK);
    assert_true(scale == 1.0);
    free(copy);
    tcb_binding_sequence_free(s);
    tcb_sequence_free(&raw);

    assert_null(tcb_binding_sequence_load("/nowhere/config.json", "synth", "quadruped_walk", NULL, &err));
    assert_int_equal(err.code, TCB_ERR_IO);
    assert_null(tcb_binding_sequence_load(path, "synth", "nope", NULL, &err));
    assert_non_null(strstr(err.msg, "has no sequence named 'nope'"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_info),
        cmocka_unit_test(test_pair_metrics_is_the_cells_row),
        cmocka_unit_test(test_pair_metrics_errors),
        cmocka_unit_test_setup_teardown(test_split_json, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_run_load_sequence, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_binding_sequence, tu_setup_tmpdir, tu_teardown_tmpdir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/* The results store: cell files round trip, malformed files are rejected
 * with the file and key named, scans come back sorted, saves leave no
 * temporaries behind. */
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

#include "tcb/fsutil.h"
#include "tcb/json.h"
#include "tcb/binding.h"
#include "tcb/results.h"
#include "tcb/tcb.h"
#include "testutil.h"

/* A fully populated cell; with_cd = 0 models a method without reconstruction. */
static void make_cell(tcb_cell_result *c, const char *dataset, const char *sequence,
                      const char *method, int seed, int with_cd, tcb_pair_record *pairs)
{
    memset(c, 0, sizeof *c);
    snprintf(c->dataset, sizeof c->dataset, "%s", dataset);
    snprintf(c->sequence, sizeof c->sequence, "%s", sequence);
    snprintf(c->role, sizeof c->role, "test");
    snprintf(c->method, sizeof c->method, "%s", method);
    snprintf(c->method_impl, sizeof c->method_impl, "atlas");
    c->params_json = "{\"lr\":0.001,\"patches\":10,\"name\":\"x\"}";
    c->seed = seed;
    c->status = TCB_CELL_OK;
    snprintf(c->git_revision, sizeof c->git_revision, "abc1234");
    c->load_s = 0.25, c->fit_s = 12.5, c->eval_s = 1.0 / 3.0;
    c->peak_rss_kb = 123456;
    snprintf(c->split_path, sizeof c->split_path, "splits/%s/%s.json", dataset, sequence);
    c->split_seed = 2021;
    c->n_pairs = 3;
    c->pairs = pairs;
    tcb_summary_init(&c->summary);
    for (int p = 0; p < 3; p++) {
        tcb_pair_metrics m = {0};
        for (int k = 0; k < 4; k++) {
            double e = 0.01 * (p + 1) + 0.001 * k;
            tcb_stat_push(&m.sl2, e);
            tcb_stat_push(&m.sl2sq, e * e);
            tcb_stat_push(&m.rank, 0.1 * k);
        }
        for (int s = 0; s < TCB_PCK_STEPS; s++) m.pck[s] = s / 99.0;
        m.auc = 0.5 + 0.1 * p;
        for (int k = 0; k < 4; k++) tcb_stat_push(&m.geo, 0.03 * (p + 1) + 0.007 * k);
        for (int s = 0; s < TCB_GEO_PCK_STEPS; s++) m.geo_pck[s] = s / 123.0;
        m.geo_auc = 0.4 + 0.1 / 3 * p;
        m.geo_unreachable = p;
        double cd = with_cd ? 1e-4 * (p + 1) / 3.0 : NAN;
        pairs[p] = (tcb_pair_record){p,   (p + 2) % 5, m.sl2, m.sl2sq,   m.rank,
                                     m.auc, cd,        m.geo, m.geo_auc, m.geo_unreachable};
        tcb_summary_add_pair(&c->summary, &m, cd);
    }
}

static void assert_stat_equal(const tcb_stat *a, const tcb_stat *b)
{
    assert_true(a->n == b->n);
    assert_true(a->mean == b->mean);
    assert_true(a->m2 == b->m2);
}

static void assert_cells_equal(const tcb_cell_result *a, const tcb_cell_result *b)
{
    assert_string_equal(a->dataset, b->dataset);
    assert_string_equal(a->sequence, b->sequence);
    assert_string_equal(a->role, b->role);
    assert_string_equal(a->method, b->method);
    assert_string_equal(a->method_impl, b->method_impl);
    assert_string_equal(a->params_json, b->params_json);
    assert_int_equal(a->seed, b->seed);
    assert_int_equal(a->status, b->status);
    assert_string_equal(a->message, b->message);
    assert_string_equal(a->git_revision, b->git_revision);
    assert_true(a->load_s == b->load_s && a->fit_s == b->fit_s && a->eval_s == b->eval_s);
    assert_int_equal(a->peak_rss_kb, b->peak_rss_kb);
    assert_string_equal(a->split_path, b->split_path);
    assert_true(a->split_seed == b->split_seed);
    assert_int_equal(a->n_pairs, b->n_pairs);
    for (int p = 0; p < a->n_pairs; p++) {
        const tcb_pair_record *x = &a->pairs[p], *y = &b->pairs[p];
        assert_int_equal(x->i, y->i);
        assert_int_equal(x->j, y->j);
        assert_stat_equal(&x->sl2, &y->sl2);
        assert_stat_equal(&x->sl2sq, &y->sl2sq);
        assert_stat_equal(&x->rank, &y->rank);
        assert_true(x->auc == y->auc);
        assert_true(isnan(x->cd) ? isnan(y->cd) : x->cd == y->cd);
        assert_stat_equal(&x->geo, &y->geo);
        assert_true(x->geo.n == 0 || x->geo_auc == y->geo_auc);
        assert_int_equal(x->geo_unreachable, y->geo_unreachable);
    }
    const tcb_summary *s = &a->summary, *t = &b->summary;
    assert_int_equal(s->n_pairs, t->n_pairs);
    assert_stat_equal(&s->sl2, &t->sl2);
    assert_stat_equal(&s->sl2sq, &t->sl2sq);
    assert_stat_equal(&s->rank, &t->rank);
    assert_stat_equal(&s->auc, &t->auc);
    assert_stat_equal(&s->cd, &t->cd);
    assert_memory_equal(s->pck, t->pck, sizeof s->pck);
    assert_stat_equal(&s->geo, &t->geo);
    assert_stat_equal(&s->geo_auc, &t->geo_auc);
    assert_memory_equal(s->geo_pck, t->geo_pck, sizeof s->geo_pck);
    assert_true(s->geo_unreachable == t->geo_unreachable);
    assert_stat_equal(&s->corr, &t->corr);
    assert_stat_equal(&s->corr_mesh, &t->corr_mesh);
    assert_string_equal(a->normals, b->normals);
    assert_int_equal(a->n_surface ? a->surface_frame : 0, b->n_surface ? b->surface_frame : 0);
    assert_int_equal(a->n_clips, b->n_clips);
    assert_string_equal(a->clips_path, b->clips_path);
    assert_true(a->clips_seed == b->clips_seed);
    if (a->n_clips) assert_memory_equal(a->clips, b->clips, (size_t)a->n_clips * sizeof *a->clips);
    for (int m = 0; m < TCB_N_RECON; m++) assert_stat_equal(&s->recon[m], &t->recon[m]);
    assert_int_equal(a->n_surface, b->n_surface);
    assert_int_equal(a->n_surface ? a->surface_samples : 0, b->n_surface ? b->surface_samples : 0);
    if (a->n_surface) assert_memory_equal(a->surface, b->surface, (size_t)a->n_surface * sizeof *a->surface);
}

/* Three evaluated frames' reconstruction metrics into c (records in rows[3]). */
static void add_surface(tcb_cell_result *c, tcb_surface_record *rows)
{
    c->surface_samples = 1000;
    c->surface_frame = TCB_RECON_FRAME_BOX;
    snprintf(c->normals, sizeof c->normals, "gt");
    c->n_surface = 3;
    c->surface = rows;
    for (int k = 0; k < 3; k++) {
        rows[k].frame = 2 * k + 1;
        for (int m = 0; m < TCB_N_RECON; m++) {
            rows[k].v[m] = (m ? 0.9 : 1e-4) / (k + m + 1.0);
            tcb_stat_push(&c->summary.recon[m], rows[k].v[m]);
        }
    }
}

/* What a test cell carries besides the pairs. */
enum { WITH_CLIPS = 1, WITH_SURFACE = 2 };

/* Two clips of the clip protocol into c (records in clips[2]); the first
 * has DynoSurf's Corr too, the second none (a null in its row). */
static void add_clips(tcb_cell_result *c, tcb_clip_record *clips)
{
    snprintf(c->clips_path, sizeof c->clips_path, "splits/%s/%s.clips.json", c->dataset, c->sequence);
    c->clips_seed = 2021;
    c->n_clips = 2;
    c->clips = clips;
    for (int k = 0; k < 2; k++) {
        clips[k].start = 3 * k + 1;
        clips[k].corr = 0;
        for (int t = 0; t < TCB_CLIP_FRAMES - 1; t++) {
            clips[k].err[t] = 0.001 * (t + 1) / (k + 3.0);
            clips[k].corr += clips[k].err[t] / (TCB_CLIP_FRAMES - 1);
        }
        tcb_stat_push(&c->summary.corr, clips[k].corr);
        clips[k].corr_mesh = k == 0 ? 1.25 * clips[k].corr : NAN;
    }
    tcb_stat_push(&c->summary.corr_mesh, clips[0].corr_mesh);
}

static void round_trip(int with_cd, int with)
{
    char dir[512], path[4096];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_pair_record pairs[3];
    tcb_clip_record clips[2];
    tcb_surface_record surface[3];
    tcb_cell_result c, back;
    tcb_error err = {0};
    make_cell(&c, "anim", "horse", "OUR", 3, with_cd, pairs);
    if (with & WITH_CLIPS) add_clips(&c, clips);
    if (with & WITH_SURFACE) add_surface(&c, surface);
    assert_int_equal(tcb_cell_path(path, sizeof path, dir, "anim", "horse", "OUR", 3, &err), 0);
    assert_int_equal(tcb_cell_save(path, &c, &err), TCB_OK);
    assert_int_equal(tcb_cell_load(path, &back, &err), TCB_OK);
    assert_cells_equal(&c, &back);
    assert_true(with_cd ? back.summary.cd.n == 3 : back.summary.cd.n == 0);
    tcb_cell_free(&back);
    tu_remove_tree(dir);
}

static void test_round_trip_with_cd(void **state)
{
    (void)state;
    round_trip(1, 0);
}

static void test_round_trip_without_cd(void **state)
{
    (void)state;
    round_trip(0, 0);
}

static void test_failed_cell_round_trip(void **state)
{
    (void)state;
    char dir[512], path[4096];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_cell_result c, back;
    tcb_error err = {0};
    tcb_pair_record pairs[3];
    make_cell(&c, "ama", "crane", "DSR", 0, 1, pairs);
    c.status = TCB_CELL_DIVERGED;
    c.n_pairs = 0;
    c.pairs = NULL;
    tcb_summary_init(&c.summary);
    c.summary.sl2.mean = NAN; /* non-finite metrics are stored as null */
    snprintf(c.message, sizeof c.message, "loss is NaN at iteration 12");
    assert_int_equal(tcb_cell_path(path, sizeof path, dir, "ama", "crane", "DSR", 0, &err), 0);
    assert_int_equal(tcb_cell_save(path, &c, &err), TCB_OK);
    assert_int_equal(tcb_cell_load(path, &back, &err), TCB_OK);
    assert_int_equal(back.status, TCB_CELL_DIVERGED);
    assert_string_equal(back.message, "loss is NaN at iteration 12");
    assert_true(isnan(back.summary.sl2.mean));
    assert_int_equal(back.n_pairs, 0);
    assert_null(back.pairs);
    tcb_cell_free(&back);
    tu_remove_tree(dir);
}

static void test_save_leaves_no_temporaries(void **state)
{
    (void)state;
    char dir[512], path[4096], cell_dir[4096];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_pair_record pairs[3];
    tcb_cell_result c;
    tcb_error err = {0};
    make_cell(&c, "anim", "cat", "AN", 0, 1, pairs);
    assert_int_equal(tcb_cell_path(path, sizeof path, dir, "anim", "cat", "AN", 0, &err), 0);
    assert_int_equal(tcb_cell_save(path, &c, &err), TCB_OK);
    assert_int_equal(tcb_cell_save(path, &c, &err), TCB_OK); /* overwrite */
    snprintf(cell_dir, sizeof cell_dir, "%s/cells/anim/cat/AN", dir);
    DIR *d = opendir(cell_dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
        assert_string_equal(e->d_name, "seed_0.json");
        n++;
    }
    closedir(d);
    assert_int_equal(n, 1);
    tu_remove_tree(dir);
}

static void test_cell_path_rejects_escapes(void **state)
{
    (void)state;
    char path[4096];
    tcb_error err = {0};
    assert_int_equal(tcb_cell_path(path, sizeof path, "run", "a/b", "s", "m", 0, &err),
                     TCB_ERR_INPUT);
    assert_int_equal(tcb_cell_path(path, sizeof path, "run", "d", "..", "m", 0, &err),
                     TCB_ERR_INPUT);
    assert_int_equal(tcb_cell_path(path, sizeof path, "run", "d", "s", "m", 7, &err), TCB_OK);
    assert_string_equal(path, "run/cells/d/s/m/seed_7.json");
}

/* A new cell records this library's version; a loaded one keeps the
 * version that wrote it when saved again, and the binding's text of a cell
 * is its file's JSON. */
static void test_version_kept_and_binding_text(void **state)
{
    (void)state;
    char dir[512], path[4096], again[4200];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_pair_record pairs[3];
    tcb_cell_result c, back;
    tcb_error err = {0};
    make_cell(&c, "anim", "horse", "OUR", 0, 0, pairs);
    assert_int_equal(tcb_cell_path(path, sizeof path, dir, "anim", "horse", "OUR", 0, &err), 0);
    assert_int_equal(tcb_cell_save(path, &c, &err), TCB_OK);
    assert_int_equal(tcb_cell_load(path, &back, &err), TCB_OK);
    assert_string_equal(back.tcbench_version, TCB_VERSION);
    tcb_cell_free(&back);

    cJSON *root, *text;
    assert_int_equal(tcb_json_load(path, &root, &err), TCB_OK);
    cJSON_ReplaceItemInObject(root, "tcbench_version", cJSON_CreateString("0.0.9"));
    assert_int_equal(tcb_json_save(path, root, &err), TCB_OK);
    assert_int_equal(tcb_cell_load(path, &back, &err), TCB_OK);
    snprintf(again, sizeof again, "%s/again.json", dir);
    assert_int_equal(tcb_cell_save(again, &back, &err), TCB_OK);
    tcb_cell_free(&back);
    assert_int_equal(tcb_cell_load(again, &back, &err), TCB_OK);
    assert_string_equal(back.tcbench_version, "0.0.9");
    tcb_cell_free(&back);

    char *json = tcb_binding_cell_json(path, &err);
    assert_non_null(json);
    assert_int_equal(tcb_json_parse(json, "binding", &text, &err), TCB_OK);
    tcb_binding_free(json);
    assert_true(cJSON_Compare(root, text, 1));
    cJSON_Delete(text);
    cJSON_Delete(root);
    assert_null(tcb_binding_cell_json(dir, &err));
    tu_remove_tree(dir);
}

/* ------------------------------------------------------ malformed files */

typedef void (*json_edit)(cJSON *root);

/* Saves a valid cell (with two clips when with_clips), applies `edit` to
 * its JSON, and expects loading to fail with TCB_ERR_INPUT naming the file
 * and `key`. */
static void expect_rejected_cell(json_edit edit, const char *key, int with)
{
    char dir[512], path[4096];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_pair_record pairs[3];
    tcb_clip_record clips[2];
    tcb_surface_record surface[3];
    tcb_cell_result c, back;
    tcb_error err = {0};
    make_cell(&c, "anim", "cat", "AN", 0, 1, pairs);
    if (with & WITH_CLIPS) add_clips(&c, clips);
    if (with & WITH_SURFACE) add_surface(&c, surface);
    assert_int_equal(tcb_cell_path(path, sizeof path, dir, "anim", "cat", "AN", 0, &err), 0);
    assert_int_equal(tcb_cell_save(path, &c, &err), TCB_OK);
    cJSON *root;
    assert_int_equal(tcb_json_load(path, &root, &err), TCB_OK);
    edit(root);
    assert_int_equal(tcb_json_save(path, root, &err), TCB_OK);
    cJSON_Delete(root);
    assert_int_equal(tcb_cell_load(path, &back, &err), TCB_ERR_INPUT);
    if (!strstr(err.msg, path) || !strstr(err.msg, key))
        fail_msg("message \"%s\" does not name %s and %s", err.msg, path, key);
    assert_null(back.pairs);
    assert_null(back.clips);
    assert_null(back.surface);
    assert_null(back.params_json);
    tu_remove_tree(dir);
}

static void expect_rejected(json_edit edit, const char *key) { expect_rejected_cell(edit, key, 0); }

static void drop_status(cJSON *r) { cJSON_DeleteItemFromObject(r, "status"); }
static void seed_as_string(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "seed", cJSON_CreateString("0"));
}
static void wrong_format(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format", cJSON_CreateString("tcbench-cell/0"));
}
static void unknown_status(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "status", cJSON_CreateString("meh"));
}
static void mean_as_string(cJSON *r)
{
    cJSON *sl2 = cJSON_GetObjectItem(cJSON_GetObjectItem(r, "summary"), "sl2");
    cJSON_ReplaceItemInObject(sl2, "mean", cJSON_CreateString("0.1"));
}
static void short_pck(cJSON *r)
{
    cJSON_DeleteItemFromArray(cJSON_GetObjectItem(cJSON_GetObjectItem(r, "summary"), "pck"), 0);
}
static void drop_pair(cJSON *r) { cJSON_DeleteItemFromArray(cJSON_GetObjectItem(r, "pairs"), 1); }
static void extra_key(cJSON *r) { cJSON_AddNumberToObject(r, "colour", 3); }
static void params_as_array(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "params", cJSON_CreateArray());
}
static void drop_fit_time(cJSON *r)
{
    cJSON_DeleteItemFromObject(cJSON_GetObjectItem(r, "timings"), "fit_s");
}

static void test_rejects_missing_key(void **state)
{
    (void)state;
    expect_rejected(drop_status, "status");
    expect_rejected(drop_fit_time, "timings.fit_s");
}

static void test_rejects_wrong_type(void **state)
{
    (void)state;
    expect_rejected(seed_as_string, "seed");
    expect_rejected(mean_as_string, "summary.sl2.mean");
    expect_rejected(params_as_array, "params");
    expect_rejected(unknown_status, "status");
}

static void test_rejects_wrong_format(void **state)
{
    (void)state;
    expect_rejected(wrong_format, "format");
}

static void test_rejects_inconsistent_shapes(void **state)
{
    (void)state;
    expect_rejected(short_pck, "summary.pck");
    expect_rejected(drop_pair, "pairs");
    expect_rejected(extra_key, "colour");
}

/* The geodesic keys go together, and so do a pair's geodesic columns. */
static void drop_geo_pck(cJSON *r)
{
    cJSON_DeleteItemFromObject(cJSON_GetObjectItem(r, "summary"), "geo_pck");
}
static void half_null_geo(cJSON *r)
{
    cJSON *row = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "pairs"), 1);
    cJSON_ReplaceItemInArray(row, 11, cJSON_CreateNull());
}
static void too_many_unreachable(cJSON *r)
{
    cJSON *row = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "pairs"), 0);
    cJSON_ReplaceItemInArray(row, 14, cJSON_CreateNumber(5)); /* n is 4 */
}
static void thirteen_columns(cJSON *r)
{
    cJSON *cols = cJSON_GetObjectItem(r, "pair_columns");
    cJSON_DeleteItemFromArray(cols, 14);
    cJSON_DeleteItemFromArray(cols, 13);
}

static void test_rejects_partial_geodesic(void **state)
{
    (void)state;
    expect_rejected(drop_geo_pck, "summary.geo_pck");
    expect_rejected(half_null_geo, "pairs[1]");
    expect_rejected(too_many_unreachable, "pairs[0]");
    expect_rejected(thirteen_columns, "pair_columns");
}

/* What a cell file written before the geodesic error looks like: no
 * summary geodesic keys, the first 11 pair columns. */
static void to_old_format(cJSON *root)
{
    cJSON *summary = cJSON_GetObjectItem(root, "summary");
    static const char *const geo_keys[] = {"geo", "geo_auc", "geo_pck", "geo_unreachable"};
    for (int k = 0; k < 4; k++) cJSON_DeleteItemFromObject(summary, geo_keys[k]);
    cJSON *cols = cJSON_GetObjectItem(root, "pair_columns"), *row;
    while (cJSON_GetArraySize(cols) > 11) cJSON_DeleteItemFromArray(cols, 11);
    cJSON_ArrayForEach(row, cJSON_GetObjectItem(root, "pairs"))
        while (cJSON_GetArraySize(row) > 11) cJSON_DeleteItemFromArray(row, 11);
}

/* The cell file at path through cJSON, edited by `edit` (NULL: none). */
static void rewrite(const char *path, json_edit edit)
{
    cJSON *root;
    tcb_error err = {0};
    assert_int_equal(tcb_json_load(path, &root, &err), TCB_OK);
    if (edit) edit(root);
    assert_int_equal(tcb_json_save(path, root, &err), TCB_OK);
    cJSON_Delete(root);
}

/* An older cell loads with no geodesic values and everything else as
 * written; saved again (with null geodesic columns) it loads the same.
 * (cJSON prints 15 significant digits where they nearly round-trip, so the
 * reference is the file after one pass through cJSON, which a second pass
 * leaves as it is.) */
static void test_loads_cell_without_geodesic(void **state)
{
    (void)state;
    char dir[512], path[4096];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_pair_record pairs[3];
    tcb_cell_result c, ref, old, again;
    tcb_error err = {0};
    make_cell(&c, "anim", "cat", "AN", 0, 1, pairs);
    assert_int_equal(tcb_cell_path(path, sizeof path, dir, "anim", "cat", "AN", 0, &err), 0);
    assert_int_equal(tcb_cell_save(path, &c, &err), TCB_OK);
    rewrite(path, NULL);
    assert_int_equal(tcb_cell_load(path, &ref, &err), TCB_OK);
    rewrite(path, to_old_format);
    assert_int_equal(tcb_cell_load(path, &old, &err), TCB_OK);
    assert_true(old.summary.geo.n == 0 && old.summary.geo_auc.n == 0);
    /* the Euclidean numbers untouched: the reference with its geodesic ones set aside */
    for (int p = 0; p < 3; p++) {
        assert_true(old.pairs[p].geo.n == 0);
        ref.pairs[p].geo = (tcb_stat){0}, ref.pairs[p].geo_unreachable = 0;
    }
    ref.summary.geo = ref.summary.geo_auc = (tcb_stat){0};
    memset(ref.summary.geo_pck, 0, sizeof ref.summary.geo_pck);
    ref.summary.geo_unreachable = 0;
    assert_cells_equal(&ref, &old);
    assert_int_equal(tcb_cell_save(path, &old, &err), TCB_OK);
    assert_int_equal(tcb_cell_load(path, &again, &err), TCB_OK);
    assert_cells_equal(&old, &again);
    tcb_cell_free(&ref);
    tcb_cell_free(&old);
    tcb_cell_free(&again);
    tu_remove_tree(dir);
}

/* A cell with clips: saved and loaded back the same; damaged clip keys
 * are refused naming them. */
static void test_round_trip_with_clips(void **state)
{
    (void)state;
    round_trip(0, WITH_CLIPS);
}

static void test_round_trip_with_surface(void **state)
{
    (void)state;
    round_trip(1, WITH_SURFACE | WITH_CLIPS);
}

static cJSON *surface_of(cJSON *r) { return cJSON_GetObjectItem(r, "surface"); }
static void drop_nc(cJSON *r) { cJSON_DeleteItemFromObject(cJSON_GetObjectItem(r, "summary"), "nc"); }
static void drop_surface(cJSON *r) { cJSON_DeleteItemFromObject(r, "surface"); }
static void surface_columns_swapped(cJSON *r)
{
    cJSON_ReplaceItemInArray(cJSON_GetObjectItem(surface_of(r), "columns"), 1, cJSON_CreateString("nc"));
}
static void surface_frames_unsorted(cJSON *r)
{
    cJSON *row = cJSON_GetArrayItem(cJSON_GetObjectItem(surface_of(r), "rows"), 2);
    cJSON_ReplaceItemInArray(row, 0, cJSON_CreateNumber(1));
}
static void surface_row_short(cJSON *r)
{
    cJSON_DeleteItemFromArray(cJSON_GetArrayItem(cJSON_GetObjectItem(surface_of(r), "rows"), 0), 4);
}
static void surface_samples_zero(cJSON *r)
{
    cJSON_ReplaceItemInObject(surface_of(r), "samples", cJSON_CreateNumber(0));
}

/* The reconstruction keys go together: summary and rows agree, columns in
 * order, frames ascending, each row complete. */
static void test_rejects_bad_surface(void **state)
{
    (void)state;
    expect_rejected_cell(drop_nc, "summary.nc: over 0 frames, but the cell has 3 surface rows", WITH_SURFACE);
    expect_rejected_cell(drop_surface, "summary.cdl2: over 3 frames, but the cell has 0", WITH_SURFACE);
    expect_rejected_cell(surface_columns_swapped, "surface.columns", WITH_SURFACE);
    expect_rejected_cell(surface_frames_unsorted, "surface.rows[2]: frame 1 after frame 3", WITH_SURFACE);
    expect_rejected_cell(surface_row_short, "surface.rows[0]", WITH_SURFACE);
    expect_rejected_cell(surface_samples_zero, "surface.samples", WITH_SURFACE);
}

static void drop_corr(cJSON *r) { cJSON_DeleteItemFromObject(cJSON_GetObjectItem(r, "summary"), "corr"); }
static void clip_frames_16(cJSON *r)
{
    cJSON_ReplaceItemInObject(cJSON_GetObjectItem(r, "clips"), "clip_frames", cJSON_CreateNumber(16));
}
static void short_clip_errors(cJSON *r)
{
    cJSON *row = cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetObjectItem(r, "clips"), "rows"), 1);
    cJSON_DeleteItemFromArray(cJSON_GetArrayItem(row, 2), 0);
}
static void drop_clip_row(cJSON *r)
{
    cJSON_DeleteItemFromArray(cJSON_GetObjectItem(cJSON_GetObjectItem(r, "clips"), "rows"), 0);
}
static void corr_without_clips(cJSON *r)
{
    cJSON *corr = cJSON_Duplicate(cJSON_GetObjectItem(cJSON_GetObjectItem(r, "summary"), "auc"), 1);
    cJSON_AddItemToObject(cJSON_GetObjectItem(r, "summary"), "corr", corr);
}

static void test_rejects_bad_clips(void **state)
{
    (void)state;
    expect_rejected_cell(drop_corr, "summary.corr: absent", 1);
    expect_rejected_cell(clip_frames_16, "clips.clip_frames", 1);
    expect_rejected_cell(short_clip_errors, "clips.rows[1]", 1);
    expect_rejected_cell(drop_clip_row, "clips.rows", 1);
    expect_rejected_cell(corr_without_clips, "summary.corr: over other clips", 0);
}

static void test_rejects_bad_json(void **state)
{
    (void)state;
    char dir[512], path[4096];
    tu_make_tmpdir(dir, sizeof dir);
    tu_write_text(dir, "seed_0.json", "{\"format\": \"tcbench-cell/1\",\n  \"dataset\": }\n", path,
                  sizeof path);
    tcb_cell_result c;
    tcb_error err = {0};
    assert_int_equal(tcb_cell_load(path, &c, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, ":2:"));
    tu_remove_tree(dir);
}

/* ------------------------------------------------------------------ scan */

static void test_scan_sorts_and_skips_non_cells(void **state)
{
    (void)state;
    char dir[512], path[4096], junk[4096];
    tu_make_tmpdir(dir, sizeof dir);
    static const struct { const char *d, *s, *m; int seed; } order[] = {
        {"ama", "crane", "OUR", 0},    {"anim", "cat", "AN", 2},  {"anim", "cat", "AN", 10},
        {"anim", "cat", "OUR", 0},     {"anim", "horse", "AN", 0},
    };
    const int n_cells = (int)(sizeof order / sizeof order[0]);
    tcb_error err = {0};
    for (int k = n_cells - 1; k >= 0; k--) { /* written out of order */
        int w = (k * 3) % n_cells;
        tcb_pair_record pairs[3];
        tcb_cell_result c;
        make_cell(&c, order[w].d, order[w].s, order[w].m, order[w].seed, w % 2, pairs);
        assert_int_equal(tcb_cell_path(path, sizeof path, dir, order[w].d, order[w].s, order[w].m,
                                       order[w].seed, &err), 0);
        assert_int_equal(tcb_cell_save(path, &c, &err), TCB_OK);
    }
    /* Neither an atomic-write leftover nor a non-JSON file is a cell. */
    snprintf(junk, sizeof junk, "%s/cells/anim/cat/AN", dir);
    tu_write_text(junk, "seed_3.json.tmp-abc123", "{", path, sizeof path);
    tu_write_text(junk, "notes.txt", "hello", path, sizeof path);
    tcb_cell_result *cells;
    int n;
    assert_int_equal(tcb_results_scan(dir, &cells, &n, &err), TCB_OK);
    assert_int_equal(n, n_cells);
    for (int k = 0; k < n; k++) {
        assert_string_equal(cells[k].dataset, order[k].d);
        assert_string_equal(cells[k].sequence, order[k].s);
        assert_string_equal(cells[k].method, order[k].m);
        assert_int_equal(cells[k].seed, order[k].seed);
        tcb_cell_free(&cells[k]);
    }
    free(cells);
    tu_remove_tree(dir);
}

static void test_scan_rejects_misplaced_and_missing(void **state)
{
    (void)state;
    char dir[512], path[4096], other[4096];
    tu_make_tmpdir(dir, sizeof dir);
    tcb_cell_result *cells;
    int n;
    tcb_error err = {0};
    assert_int_equal(tcb_results_scan(dir, &cells, &n, &err), TCB_ERR_IO); /* no cells/ */
    tcb_pair_record pairs[3];
    tcb_cell_result c;
    make_cell(&c, "anim", "cat", "AN", 0, 1, pairs);
    /* A cell copied under another seed's name would be counted twice. */
    snprintf(other, sizeof other, "%s/cells/anim/cat/AN/seed_1.json", dir);
    assert_int_equal(tcb_cell_save(other, &c, &err), TCB_OK);
    assert_int_equal(tcb_results_scan(dir, &cells, &n, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, other));
    assert_int_equal(tcb_cell_path(path, sizeof path, dir, "anim", "cat", "AN", 0, &err), 0);
    assert_non_null(strstr(err.msg, path));
    assert_null(cells);
    tu_remove_tree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_with_cd),
        cmocka_unit_test(test_round_trip_without_cd),
        cmocka_unit_test(test_failed_cell_round_trip),
        cmocka_unit_test(test_save_leaves_no_temporaries),
        cmocka_unit_test(test_cell_path_rejects_escapes),
        cmocka_unit_test(test_version_kept_and_binding_text),
        cmocka_unit_test(test_rejects_missing_key),
        cmocka_unit_test(test_rejects_wrong_type),
        cmocka_unit_test(test_rejects_wrong_format),
        cmocka_unit_test(test_rejects_inconsistent_shapes),
        cmocka_unit_test(test_rejects_partial_geodesic),
        cmocka_unit_test(test_loads_cell_without_geodesic),
        cmocka_unit_test(test_round_trip_with_clips),
        cmocka_unit_test(test_round_trip_with_surface),
        cmocka_unit_test(test_rejects_bad_surface),
        cmocka_unit_test(test_rejects_bad_clips),
        cmocka_unit_test(test_rejects_bad_json),
        cmocka_unit_test(test_scan_sorts_and_skips_non_cells),
        cmocka_unit_test(test_scan_rejects_misplaced_and_missing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

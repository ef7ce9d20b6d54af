/* `tcbench score` (tcb/score.h): a directory of predictions scored as one
 * cell of a run, by the code that scores a method's cells.
 *
 * Everything that can be checked without the data (the names, the label,
 * an existing cell, the directory's files) is checked first, so a mistake
 * costs no sequence load; then the sequence and its split are obtained as
 * `tcbench run` obtains them (a missing split is drawn and saved exactly
 * as run would: the same file every method's cells use), every pair is
 * read and scored in memory, and the cell is written atomically only when
 * all of them were. */
#include "tcb/score.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "harness/internal.h"
#include "tcb/fsutil.h"
#include "tcb/progress.h"

/* What a scored cell names as its method: not a registered method, only
 * the identity the cell file records (method_impl). */
static const tcb_method_ops scored_ops = {.name = "scored"};

typedef struct target {
    const tcb_dataset_spec *d;
    const tcb_sequence_spec *s;
} target;

/* The messages name the option that chose what is missing. */
static int find_target(const tcb_config *cfg, const tcb_score_opts *o, target *t, tcb_error *err)
{
    int rc = tcb_config_find_sequence(cfg, o->dataset, o->sequence, &t->d, &t->s, err);
    if (rc) tcb_error_prefix(err, "%s", t->d ? "--sequence: " : "--dataset: ");
    return rc;
}

/* A configured method's label would put the scored cell among the cells
 * `tcbench run` owns (and skips, or recomputes with --force): refused. */
static int check_label(const tcb_config *cfg, const char *label, tcb_error *err)
{
    if (strlen(label) >= sizeof ((tcb_cell_result *)0)->method)
        return tcb_fail(err, TCB_ERR_INPUT, "--name: '%s' is longer than %zu characters", label,
                        sizeof ((tcb_cell_result *)0)->method - 1);
    for (int k = 0; k < cfg->n_methods; k++)
        if (!strcmp(cfg->methods[k].label, label))
            return tcb_fail(err, TCB_ERR_INPUT,
                            "--name: %s has a method labelled '%s' (its cells are tcbench run's); choose another name",
                            cfg->path, label);
    return TCB_OK;
}

/* {"pred_dir": dir}, escaped as JSON; malloc'ed, NULL when out of memory. */
static char *params_json(const char *dir)
{
    cJSON *o = cJSON_CreateObject();
    char *text = o && cJSON_AddStringToObject(o, "pred_dir", dir) ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    char *copy = text ? strdup(text) : NULL;
    cJSON_free(text);
    return copy;
}

/* Every pair of the split, read from <dir>/<k>.npy and scored into c. */
static int score_pairs(const char *dir, const tcb_sequence *seq, const tcb_split *split, tcb_cell_result *c,
                       tcb_error *err)
{
    size_t nv = (size_t)seq->n_verts;
    int32_t *pred = malloc(nv * sizeof *pred);
    float *moved = malloc(nv * 3 * sizeof *moved);
    c->pairs = calloc((size_t)split->n_pairs + 1, sizeof *c->pairs);
    c->n_pairs = split->n_pairs;
    tcb_pair_scorer scorer = {0};
    int rc = !pred || !moved || !c->pairs ? tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %zu vertices", nv) : TCB_OK;
    if (!rc) rc = tcb_pair_scorer_init(&scorer, seq, err);
    for (int k = 0; !rc && k < split->n_pairs; k++) {
        char path[TCB_PATH_MAX];
        int is_points = 0;
        rc = tcb_path_join(path, sizeof path, err, "%s/%d.npy", dir, k);
        if (!rc) rc = tcb_score_read_prediction(path, seq->n_verts, pred, moved, &is_points, err);
        if (rc) break;
        tcb_pair_prediction p = {split->pairs[2 * k], split->pairs[2 * k + 1], is_points ? moved : NULL, pred, NAN,
                                 NULL};
        rc = tcb_cell_score_pair(&scorer, &p, &c->pairs[k], &c->summary, NULL, err);
        if (rc) tcb_error_prefix(err, "%s: ", path);
    }
    tcb_pair_scorer_free(&scorer);
    free(pred);
    free(moved);
    return rc;
}

/* The cell as tcb/score.h describes it, from the loaded sequence and split. */
static int build_cell(const tcb_config *cfg, const tcb_score_opts *o, const target *t, const tcb_sequence *seq,
                      const tcb_split *split, const char *split_path, tcb_cell_result *c, tcb_error *err)
{
    char revision[64];
    tcb_git_revision(revision, sizeof revision);
    tcb_method_spec spec = {.method = "scored", .params_json = params_json(o->pred_dir)};
    if (!spec.params_json) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    snprintf(spec.label, sizeof spec.label, "%s", o->label);
    tcb_cell_job job = {.seq = seq, .split = split, .split_path = split_path, .dataset = t->d, .method = &spec,
                        .ops = &scored_ops, .seed = o->seed, .git_revision = revision};
    int rc = tcb_cell_identity(&job, c, err);
    free(spec.params_json);
    if (rc) return rc;
    snprintf(c->message, sizeof c->message, "scored from files");
    /* The cell's thread count, as a method's evaluation has it (tcb_cell_run). */
    int threads = omp_get_max_threads();
    if (cfg->threads > 0) omp_set_num_threads(cfg->threads);
    double t0 = tcb_now_seconds();
    rc = score_pairs(o->pred_dir, seq, split, c, err);
    c->eval_s = tcb_now_seconds() - t0;
    omp_set_num_threads(threads);
    return rc;
}

/* Loads what `tcbench run` loads for the sequence and builds the cell. */
static int score_cell(const tcb_config *cfg, const tcb_score_opts *o, const target *t, tcb_cell_result *c,
                      tcb_error *err)
{
    memset(c, 0, sizeof *c);
    tcb_sequence seq = {0};
    tcb_split split = {0};
    char split_path[TCB_PATH_MAX];
    double t0 = tcb_now_seconds();
    int rc = tcb_harness_load_sequence(cfg, t->d, t->s->name, NULL, &seq, err);
    if (rc) return rc;
    double load_s = tcb_now_seconds() - t0;
    rc = tcb_harness_obtain_split(cfg, t->d, t->s, &seq, split_path, sizeof split_path, &split, err);
    if (!rc) rc = build_cell(cfg, o, t, &seq, &split, split_path, c, err);
    c->load_s = load_s;
    c->peak_rss_kb = tcb_peak_rss_kb();
    tcb_split_free(&split);
    tcb_sequence_free(&seq);
    if (rc) tcb_cell_free(c);
    return rc;
}

int tcb_score(const tcb_config *cfg, const tcb_score_opts *o, char *cell_path, tcb_summary *summary,
              tcb_error *err)
{
    target t;
    char path[TCB_PATH_MAX], split_path[TCB_PATH_MAX];
    const char *run_dir = o->output ? o->output : cfg->output;
    int rc = find_target(cfg, o, &t, err);
    if (!rc) rc = check_label(cfg, o->label, err);
    if (!rc) rc = tcb_cell_path(path, sizeof path, run_dir, t.d->name, t.s->name, o->label, o->seed, err);
    if (!rc && !o->force && tcb_is_file(path))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s exists: --force replaces it", path);
    if (!rc) rc = tcb_harness_split_path(cfg, t.d, t.s, split_path, sizeof split_path, err);
    /* The split has the config's number of pairs: tcb_split_obtain refuses any other. */
    if (!rc) rc = tcb_score_check_dir(o->pred_dir, cfg->eval_pairs, split_path, err);
    if (!rc) rc = tcb_run_check_root(cfg, t.d, err);
    if (rc) return rc;
    tcb_cell_result c;
    rc = score_cell(cfg, o, &t, &c, err);
    if (rc) return rc;
    /* A scored cell joins the run directory's cells as `tcbench run`'s do:
     * not those of another config (--force replaces a cell, it does not
     * take a directory over). */
    rc = tcb_run_dir_claim(cfg, run_dir, 0, err);
    if (!rc) rc = tcb_cell_save(path, &c, err);
    if (!rc && cell_path) snprintf(cell_path, TCB_PATH_MAX, "%s", path);
    if (!rc && summary) *summary = c.summary;
    tcb_cell_free(&c);
    return rc;
}

/* `tcbench score` and the evaluator behind it (tcb/score.h): predictions
 * from a directory, an .npz or memory scored as one cell of a run, by the
 * code that scores a method's cells.
 *
 * The evaluator loads the sequence and its split once, as `tcbench run`
 * obtains them (a missing split is drawn and saved exactly as run would:
 * the same file every method's cells use); each evaluation reads and
 * scores every pair in memory, and a cell is written atomically only when
 * all of them were. `tcbench score` checks everything that can be checked
 * without the data (the names, the label, an existing cell, the files)
 * first, so a mistake costs no sequence load; the Python evaluator goes
 * through the same functions (binding.c). */
#include "tcb/score.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_internal.h"
#include "scoring/scoring.h"
#include "tcb/fsutil.h"
#include "tcb/progress.h"
#include "tcb/sysinfo.h"

/* What a scored cell names as its method: not a registered method, only
 * the identity the cell file records (method_impl). */
static const tcb_method_ops scored_ops = {.name = "scored"};

struct tcb_evaluator {
    const tcb_config *cfg;
    const tcb_dataset_spec *d;
    const tcb_sequence_spec *s;
    tcb_sequence seq;
    tcb_split split;
    char split_path[TCB_PATH_MAX];
    double load_s;
    tcb_pair_scorer scorer;
    tcb_nn *shape;      /* every frame's vertices, for the wrong-frame rule; made when needed */
    int32_t *pred;      /* [nv] one pair's vertex ids */
    float *moved;       /* [nv][3] one pair's points */
    int scored;         /* cell holds the last evaluation */
    tcb_cell_result cell;
};

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

int tcb_score_check_cell(const tcb_config *cfg, const char *run_dir, const char *dataset, const char *sequence,
                         const char *label, int seed, int force, char *path, tcb_error *err)
{
    int rc = check_label(cfg, label, err);
    if (!rc) rc = tcb_cell_path(path, TCB_PATH_MAX, run_dir, dataset, sequence, label, seed, err);
    if (!rc && !force && tcb_is_file(path)) rc = tcb_fail(err, TCB_ERR_INPUT, "%s exists: --force replaces it", path);
    return rc;
}

/* ---- the evaluator */

/* The sequence, its split and the scorer, as `tcbench run` has them. */
static int load(tcb_evaluator *ev, tcb_error *err)
{
    double t0 = tcb_now_seconds();
    int rc = tcb_run_check_root(ev->cfg, ev->d, err);
    if (!rc) rc = tcb_harness_load_sequence(ev->cfg, ev->d, ev->s, NULL, &ev->seq, err);
    if (rc) return rc;
    ev->load_s = tcb_now_seconds() - t0;
    rc = tcb_harness_obtain_split(ev->cfg, ev->d, ev->s, &ev->seq, ev->split_path, sizeof ev->split_path,
                                  &ev->split, err);
    if (!rc) rc = tcb_pair_scorer_init(&ev->scorer, &ev->seq, err);
    size_t nv = (size_t)ev->seq.n_verts;
    if (!rc && (!(ev->pred = malloc(nv * sizeof *ev->pred)) || !(ev->moved = malloc(nv * 3 * sizeof *ev->moved))))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %zu vertices", nv);
    return rc;
}

int tcb_evaluator_open(const tcb_config *cfg, const char *dataset, const char *sequence, tcb_evaluator **out,
                       tcb_error *err)
{
    *out = NULL;
    tcb_evaluator *ev = calloc(1, sizeof *ev);
    if (!ev) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    ev->cfg = cfg;
    int rc = tcb_config_find_sequence(cfg, dataset, sequence, &ev->d, &ev->s, err);
    if (!rc) rc = load(ev, err);
    if (rc) tcb_evaluator_free(ev);
    else *out = ev;
    return rc;
}

void tcb_evaluator_free(tcb_evaluator *ev)
{
    if (!ev) return;
    tcb_cell_free(&ev->cell);
    tcb_pair_scorer_free(&ev->scorer);
    tcb_nn_free(ev->shape);
    tcb_split_free(&ev->split);
    tcb_sequence_free(&ev->seq);
    free(ev->pred);
    free(ev->moved);
    free(ev);
}

const tcb_sequence *tcb_evaluator_sequence(const tcb_evaluator *ev) { return &ev->seq; }
const tcb_split *tcb_evaluator_split(const tcb_evaluator *ev) { return &ev->split; }
const char *tcb_evaluator_split_path(const tcb_evaluator *ev) { return ev->split_path; }
const tcb_cell_result *tcb_evaluator_cell(const tcb_evaluator *ev) { return ev->scored ? &ev->cell : NULL; }

/* {key: origin}, escaped as JSON; malloc'ed, NULL when out of memory. */
static char *params_json(const char *key, const char *origin)
{
    cJSON *o = cJSON_CreateObject();
    char *text = o && cJSON_AddStringToObject(o, key, origin) ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    char *copy = text ? strdup(text) : NULL;
    cJSON_free(text);
    return copy;
}

/* The cell's identity as tcb/score.h describes it (method "" until written). */
static int identity(tcb_evaluator *ev, const tcb_predictions *p, tcb_error *err)
{
    char revision[64];
    tcb_git_revision(revision, sizeof revision);
    tcb_method_spec spec = {.method = "scored", .params_json = params_json(p->key, p->origin)};
    if (!spec.params_json) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    tcb_cell_job job = {.seq = &ev->seq, .split = &ev->split, .split_path = ev->split_path, .dataset = ev->d,
                        .method = &spec, .ops = &scored_ops, .load_s = ev->load_s, .git_revision = revision};
    int rc = tcb_cell_identity(&job, &ev->cell, err);
    free(spec.params_json);
    snprintf(ev->cell.message, sizeof ev->cell.message, "%s", p->message);
    return rc;
}

/* The refusal of points in the wrong frame, completed with the split's
 * normalisation of frame j and the way out. (With normalization "none"
 * the rule refuses nothing: the raw coordinates are the frame.) */
static int wrong_frame(const tcb_sequence *seq, int k, int j, tcb_error *err)
{
    const double *c = seq->norm_shift + 3 * (size_t)j;
    char why[TCB_ERRMSG_MAX + 64];
    snprintf(why, sizeof why, "pair %d, target frame %d: %s", k, j, err->msg);
    return tcb_fail(err, TCB_ERR_INPUT,
                    "%s, not the split's frame. Its frames are normalised (normalization \"%s\"): x = (x_raw - norm_shift[j]) / "
                    "norm_scale, here norm_shift[%d] = [%.9g, %.9g, %.9g], norm_scale = %.9g (tcbench.load_sequence "
                    "gives both); --any-frame (Python: any_frame=True) scores them anyway",
                    why, tcb_config_norm_names[seq->norm], j, c[0], c[1], c[2], seq->norm_scale);
}

/* Pair k read from p, checked and scored into the cell. */
static int score_pair(tcb_evaluator *ev, const tcb_predictions *p, int k, int any_frame, tcb_error *err)
{
    const tcb_sequence *seq = &ev->seq;
    int i = ev->split.pairs[2 * k], j = ev->split.pairs[2 * k + 1], is_points = 0;
    char name[TCB_PATH_MAX] = "";
    tcb_npy a;
    int rc = p->read(p->ctx, k, &a, name, err); /* its errors name the file */
    if (rc) return rc;
    rc = tcb_score_prediction_of(&a, seq->n_verts, ev->pred, ev->moved, &is_points, err);
    tcb_npy_free(&a);
    if (!rc && is_points && !any_frame && !ev->shape)
        rc = tcb_nn_build(seq->verts, seq->n_verts * seq->n_frames, &ev->shape, err);
    if (!rc && is_points && !any_frame) {
        rc = tcb_score_check_frame(ev->shape, tcb_seq_frame(seq, j), seq->n_verts, ev->moved, seq->n_verts,
                                   seq->norm_shift + 3 * (size_t)j, seq->norm_scale, err);
        if (rc == TCB_ERR_INPUT) rc = wrong_frame(seq, k, j, err);
    }
    tcb_pair_prediction pp = {i, j, is_points ? ev->moved : NULL, ev->pred, NAN, NULL};
    if (!rc) rc = tcb_cell_score_pair(&ev->scorer, &pp, &ev->cell.pairs[k], &ev->cell.summary, NULL, err);
    if (rc) tcb_error_prefix(err, "%s: ", name);
    return rc;
}

static int score_all(tcb_evaluator *ev, const tcb_predictions *p, int any_frame, tcb_error *err)
{
    int n = ev->split.n_pairs;
    int rc = identity(ev, p, err);
    if (!rc && !(ev->cell.pairs = calloc((size_t)n + 1, sizeof *ev->cell.pairs)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d pairs", n);
    ev->cell.n_pairs = n;
    for (int k = 0; !rc && k < n; k++) rc = score_pair(ev, p, k, any_frame, err);
    return rc;
}

int tcb_evaluator_score(tcb_evaluator *ev, const tcb_predictions *p, int any_frame, tcb_error *err)
{
    tcb_cell_free(&ev->cell);
    memset(&ev->cell, 0, sizeof ev->cell);
    ev->scored = 0;
    /* The cell's thread count, as a method's evaluation has it (tcb_cell_run). */
    int threads = omp_get_max_threads();
    if (ev->cfg->threads > 0) omp_set_num_threads(ev->cfg->threads);
    double t0 = tcb_now_seconds();
    int rc = score_all(ev, p, any_frame, err);
    ev->cell.eval_s = tcb_now_seconds() - t0;
    omp_set_num_threads(threads);
    ev->cell.peak_rss_kb = tcb_peak_rss_kb();
    if (rc) tcb_cell_free(&ev->cell);
    ev->scored = !rc;
    return rc;
}

int tcb_evaluator_write(tcb_evaluator *ev, const char *run_dir, const char *label, int seed, int force,
                        char *cell_path, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    if (!ev->scored) return tcb_fail(err, TCB_ERR_INPUT, "no evaluation to write: score the predictions first");
    int rc = tcb_score_check_cell(ev->cfg, run_dir, ev->d->name, ev->s->name, label, seed, force, path, err);
    /* A scored cell joins the run directory's cells as `tcbench run`'s do:
     * not those of another config (--force replaces a cell, it does not
     * take a directory over). */
    if (!rc) rc = tcb_run_dir_claim(ev->cfg, run_dir, 0, err);
    if (rc) return rc;
    snprintf(ev->cell.method, sizeof ev->cell.method, "%s", label);
    ev->cell.seed = seed;
    rc = tcb_cell_save(path, &ev->cell, err);
    if (!rc && cell_path) snprintf(cell_path, TCB_PATH_MAX, "%s", path);
    return rc;
}

/* ---- tcbench score */

int tcb_score(const tcb_config *cfg, const tcb_score_opts *o, char *cell_path, tcb_summary *summary,
              tcb_error *err)
{
    const tcb_dataset_spec *d = NULL;
    const tcb_sequence_spec *s;
    char path[TCB_PATH_MAX], split_path[TCB_PATH_MAX];
    const char *run_dir = o->output ? o->output : cfg->output;
    int rc = tcb_config_find_sequence(cfg, o->dataset, o->sequence, &d, &s, err);
    if (rc) tcb_error_prefix(err, "%s", d ? "--sequence: " : "--dataset: ");
    if (!rc) rc = tcb_score_check_cell(cfg, run_dir, d->name, s->name, o->label, o->seed, o->force, path, err);
    if (!rc) rc = tcb_harness_split_path(cfg, d, s, split_path, sizeof split_path, err);
    tcb_predictions p = {0};
    /* The split has the config's number of pairs: tcb_split_obtain refuses any other. */
    if (!rc) rc = tcb_predictions_open(o->pred, cfg->eval_pairs, split_path, &p, err);
    if (!rc) rc = tcb_run_check_root(cfg, d, err);
    tcb_evaluator *ev = NULL;
    if (!rc) rc = tcb_evaluator_open(cfg, o->dataset, o->sequence, &ev, err);
    if (!rc) rc = tcb_evaluator_score(ev, &p, o->any_frame, err);
    if (!rc) rc = tcb_evaluator_write(ev, run_dir, o->label, o->seed, o->force, cell_path, err);
    if (!rc && summary) *summary = ev->cell.summary;
    tcb_evaluator_free(ev);
    tcb_predictions_close(&p);
    return rc;
}

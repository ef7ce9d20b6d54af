/* Flat entry points for bindings (tcb/binding.h): the structs stay here,
 * a binding sees JSON text, named arrays and a tcb_error. */
#include "tcb/binding.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scoring/scoring.h"
#include "store/cell_format.h"
#include "tcb/config.h"
#include "tcb/npy.h"
#include "tcb/predictions.h"
#include "tcb/runner.h"
#include "tcb/score.h"
#include "tcb/version.h"

/* The dtype names promise these sizes to the binding. */
_Static_assert(sizeof(float) == 4 && sizeof(double) == 8, "float32 and float64");

/* cJSON allocates with malloc, so its text goes out as it is; NULL in,
 * NULL out, the tree deleted either way. */
static char *text_of(cJSON *root, tcb_error *err)
{
    char *text = root ? cJSON_PrintUnformatted(root) : NULL;
    cJSON_Delete(root);
    if (!text) tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    return text;
}

/* item under key in o, or deleted: 0 when o or item is missing or out of
 * memory, so a builder is one chain of &&. */
static int add_item(cJSON *o, const char *key, cJSON *item)
{
    if (o && item && cJSON_AddItemToObject(o, key, item)) return 1;
    cJSON_Delete(item);
    return 0;
}

static int append(cJSON *arr, cJSON *item)
{
    if (arr && item && cJSON_AddItemToArray(arr, item)) return 1;
    cJSON_Delete(item);
    return 0;
}

/* o when ok, else deleted: NULL. */
static cJSON *kept(cJSON *o, int ok)
{
    if (ok) return o;
    cJSON_Delete(o);
    return NULL;
}

static cJSON *error_layout(void)
{
    cJSON *e = cJSON_CreateObject();
    int ok = e && cJSON_AddNumberToObject(e, "size", sizeof(tcb_error)) &&
             cJSON_AddNumberToObject(e, "msg_offset", offsetof(tcb_error, msg)) &&
             cJSON_AddNumberToObject(e, "msg_size", TCB_ERRMSG_MAX);
    return kept(e, ok);
}

char *tcb_binding_info(void)
{
    cJSON *o = cJSON_CreateObject();
    int ok = o && cJSON_AddStringToObject(o, "version", TCB_VERSION) &&
             cJSON_AddNumberToObject(o, "pck_steps", TCB_PCK_STEPS) &&
             add_item(o, "pair_columns", cJSON_CreateStringArray(tcb_cell_pair_columns, TCB_N_PAIR_COLUMNS)) &&
             add_item(o, "tcb_error", error_layout());
    return text_of(kept(o, ok), NULL);
}

void tcb_binding_free(void *p) { free(p); }

int tcb_binding_pair_metrics(const float *verts_j, int nv, const int32_t *pred, double *sq, double *rank,
                             double *pck, int n_pck, double *row, int n_row, tcb_error *err)
{
    if (n_pck != TCB_PCK_STEPS || n_row != TCB_N_PAIR_COLUMNS)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "pair metrics: the binding expects %d PCK steps and %d pair columns, the library "
                        "has %d and %d",
                        n_pck, n_row, TCB_PCK_STEPS, TCB_N_PAIR_COLUMNS);
    int rc = tcb_pair_vertex_metrics(verts_j, nv, pred, sq, rank, err);
    if (rc) return rc;
    /* The steps of tcb_pair_metrics_compute and tcb_cell_score_pair. */
    tcb_pair_metrics m;
    tcb_pair_metrics_summarize(sq, rank, nv, &m);
    tcb_pair_record rec = tcb_pair_record_of(0, 0, &m, NAN);
    tcb_pair_record_row(&rec, row);
    row[0] = row[1] = NAN;
    memcpy(pck, m.pck, sizeof m.pck);
    return TCB_OK;
}

char *tcb_binding_split_json(const char *path, tcb_error *err)
{
    tcb_split split;
    if (tcb_split_load(path, &split, err)) return NULL;
    char *text = tcb_split_json(&split);
    tcb_split_free(&split);
    if (!text) tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    return text;
}

char *tcb_binding_cell_json(const char *path, tcb_error *err)
{
    tcb_cell_result c;
    if (tcb_cell_load(path, &c, err)) return NULL;
    cJSON *root = tcb_cell_to_json(path, &c, err);
    tcb_cell_free(&c);
    return root ? text_of(root, err) : NULL;
}

tcb_sequence *tcb_binding_sequence_load(const char *config_path, const char *dataset, const char *sequence,
                                        const char *root, tcb_error *err)
{
    tcb_root_override ov = {dataset, root};
    tcb_config_opts opts = {NULL, root ? 1 : 0, &ov};
    tcb_config cfg;
    if (tcb_config_load_opts(config_path, &opts, &cfg, err)) return NULL;
    tcb_sequence *s = malloc(sizeof *s);
    int rc = s ? tcb_run_load_sequence(&cfg, dataset, sequence, s, err)
               : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    tcb_config_free(&cfg);
    if (!rc) return s;
    free(s);
    return NULL;
}

void tcb_binding_sequence_free(tcb_sequence *s)
{
    if (!s) return;
    tcb_sequence_free(s);
    free(s);
}

/* One array of a sequence as the binding sees it. */
typedef struct seq_array {
    const char *name, *dtype;
    const void *data;
    size_t item;          /* bytes per element */
    int ndim;
    long long shape[3];
} seq_array;

enum { SEQ_ARRAYS_MAX = 7 };

/* The one list both the description and the copy read, so they agree. */
static int seq_arrays(const tcb_sequence *s, seq_array *a)
{
    long long nf = s->n_frames, nv = s->n_verts;
    int n = 0;
    a[n++] = (seq_array){"verts", "float32", s->verts, 4, 3, {nf, nv, 3}};
    a[n++] = (seq_array){"faces", "int32", s->faces, 4, 2, {s->n_faces, 3}};
    if (s->areas) a[n++] = (seq_array){"areas", "float64", s->areas, 8, 1, {nf}};
    if (s->pools) a[n++] = (seq_array){"pools", "float32", s->pools, 4, 3, {nf, s->pool_size, 3}};
    if (s->norm_shift) a[n++] = (seq_array){"norm_shift", "float64", s->norm_shift, 8, 2, {nf, 3}};
    a[n++] = (seq_array){"norm_scale", "float64", &s->norm_scale, 8, 0, {0}};
    if (s->yaw) a[n++] = (seq_array){"yaw", "float64", s->yaw, 8, 1, {nf}};
    return n;
}

static size_t array_bytes(const seq_array *a)
{
    size_t n = a->item;
    for (int d = 0; d < a->ndim; d++) n *= (size_t)a->shape[d];
    return n;
}

static cJSON *array_json(const seq_array *a)
{
    cJSON *d = cJSON_CreateObject(), *shape = cJSON_CreateArray();
    int ok = add_item(d, "shape", shape) && cJSON_AddStringToObject(d, "dtype", a->dtype);
    for (int i = 0; ok && i < a->ndim; i++) ok = append(shape, cJSON_CreateNumber((double)a->shape[i]));
    return kept(d, ok);
}

static cJSON *arrays_json(const tcb_sequence *s)
{
    seq_array a[SEQ_ARRAYS_MAX];
    int n = seq_arrays(s, a);
    cJSON *o = cJSON_CreateObject();
    int ok = o != NULL;
    for (int k = 0; ok && k < n; k++) ok = add_item(o, a[k].name, array_json(&a[k]));
    return kept(o, ok);
}

static cJSON *blocks_json(const tcb_sequence *s)
{
    cJSON *arr = cJSON_CreateArray();
    int ok = arr != NULL;
    for (int k = 0; ok && k < s->n_blocks; k++) {
        cJSON *b = cJSON_CreateObject();
        ok = append(arr, b) && cJSON_AddStringToObject(b, "name", s->blocks[k].name) &&
             cJSON_AddNumberToObject(b, "start", s->blocks[k].start) &&
             cJSON_AddNumberToObject(b, "n_frames", s->blocks[k].n_frames);
    }
    return kept(arr, ok);
}

char *tcb_binding_sequence_json(const tcb_sequence *s, tcb_error *err)
{
    cJSON *o = cJSON_CreateObject();
    int ok = o && cJSON_AddStringToObject(o, "name", s->name) &&
             cJSON_AddNumberToObject(o, "n_frames", s->n_frames) &&
             cJSON_AddNumberToObject(o, "n_verts", s->n_verts) &&
             cJSON_AddNumberToObject(o, "n_faces", s->n_faces) &&
             cJSON_AddNumberToObject(o, "pool_size", s->pool_size) &&
             cJSON_AddStringToObject(o, "normalization", tcb_config_norm_names[s->norm]) &&
             cJSON_AddNumberToObject(o, "input_points", s->input_points) &&
             cJSON_AddStringToObject(o, "sampling", tcb_config_sampling_names[s->draw_with_replacement != 0]) &&
             add_item(o, "blocks", blocks_json(s)) && add_item(o, "arrays", arrays_json(s));
    return text_of(kept(o, ok), err);
}

int tcb_binding_sequence_copy(const tcb_sequence *s, const char *name, void *dst, size_t size, tcb_error *err)
{
    seq_array a[SEQ_ARRAYS_MAX];
    int n = seq_arrays(s, a);
    for (int k = 0; k < n; k++) {
        if (strcmp(a[k].name, name)) continue;
        if (size != array_bytes(&a[k]))
            return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: array %s has %zu bytes, not %zu", s->name, name,
                            array_bytes(&a[k]), size);
        if (size) memcpy(dst, a[k].data, size);
        return TCB_OK;
    }
    return tcb_fail(err, TCB_ERR_INPUT, "sequence %s has no array named '%s'", s->name, name);
}

/* ---- the evaluator */

struct tcb_binding_evaluator {
    tcb_config cfg;
    tcb_evaluator *ev;
};

tcb_binding_evaluator *tcb_binding_evaluator_open(const char *config_path, const char *dataset,
                                                  const char *sequence, const char *root, const char *variant,
                                                  tcb_error *err)
{
    tcb_root_override ov = {dataset, root};
    tcb_config_opts opts = {variant, root ? 1 : 0, &ov};
    tcb_binding_evaluator *e = calloc(1, sizeof *e);
    if (!e) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory"), NULL;
    if (tcb_config_load_opts(config_path, &opts, &e->cfg, err)) {
        free(e);
        return NULL;
    }
    if (!tcb_evaluator_open(&e->cfg, dataset, sequence, &e->ev, err)) return e;
    tcb_binding_evaluator_free(e);
    return NULL;
}

void tcb_binding_evaluator_free(tcb_binding_evaluator *e)
{
    if (!e) return;
    tcb_evaluator_free(e->ev);
    tcb_config_free(&e->cfg);
    free(e);
}

const tcb_sequence *tcb_binding_evaluator_sequence(const tcb_binding_evaluator *e)
{
    return tcb_evaluator_sequence(e->ev);
}

char *tcb_binding_evaluator_split_json(const tcb_binding_evaluator *e, tcb_error *err)
{
    char *text = tcb_split_json(tcb_evaluator_split(e->ev));
    cJSON *o = text ? cJSON_Parse(text) : NULL;
    free(text);
    int ok = o && cJSON_AddStringToObject(o, "path", tcb_evaluator_split_path(e->ev)) &&
             cJSON_AddStringToObject(o, "run_dir", e->cfg.output);
    return text_of(kept(o, ok), err);
}

/* Predictions handed over as .npy bytes, one buffer per pair. */
typedef struct memory_arrays {
    const void *const *arrays;
    const size_t *len;
} memory_arrays;

static int memory_read(void *ctx, int k, tcb_npy *a, char name[TCB_PATH_MAX], tcb_error *err)
{
    const memory_arrays *m = ctx;
    snprintf(name, TCB_PATH_MAX, "predictions[%d]", k);
    int rc = tcb_npy_parse(m->arrays[k], m->len[k], a, err);
    if (rc) tcb_error_prefix(err, "%s: ", name);
    return rc;
}

char *tcb_binding_evaluator_score(tcb_binding_evaluator *e, int n, const void *const *arrays, const size_t *len,
                                  const char *path, int any_frame, tcb_error *err)
{
    const tcb_split *split = tcb_evaluator_split(e->ev);
    memory_arrays m = {arrays, len};
    tcb_predictions p = {memory_read, &m, "pred", "memory", "scored from memory"};
    int rc = TCB_OK;
    if (path) rc = tcb_predictions_open(path, split->n_pairs, tcb_evaluator_split_path(e->ev), &p, err);
    else if (n != split->n_pairs)
        rc = tcb_fail(err, TCB_ERR_INPUT, "predictions: %d arrays for the %d pairs of %s", n, split->n_pairs,
                      tcb_evaluator_split_path(e->ev));
    if (!rc) rc = tcb_evaluator_score(e->ev, &p, any_frame, err);
    if (path) tcb_predictions_close(&p);
    if (rc) return NULL;
    cJSON *root = tcb_cell_to_json("evaluation", tcb_evaluator_cell(e->ev), err);
    return root ? text_of(root, err) : NULL;
}

char *tcb_binding_evaluator_write(tcb_binding_evaluator *e, const char *run_dir, const char *label, int seed,
                                  int force, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    if (tcb_evaluator_write(e->ev, run_dir ? run_dir : e->cfg.output, label, seed, force, path, err)) return NULL;
    char *copy = strdup(path);
    if (!copy) tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    return copy;
}

/* `tcbench inspect`: one evaluation pair recomputed and written as
 * coloured meshes (tcb/inspect.h). */
#include "tcb/inspect.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/json.h"
#include "tcb/mesh_io.h"
#include "tcb/results.h"
#include "views/cell_target.h"
#include "views/colormap.h"
#include "views/render.h"

typedef tcb_cell_target target;

/* The cell file's record of the pair, when there is one. */
typedef struct cell_row {
    int found;
    tcb_pair_record rec;
    char note[256]; /* why there is none */
} cell_row;

static void load_cell_row(const char *run_dir, const target *t, int k, cell_row *row)
{
    memset(row, 0, sizeof *row);
    char path[TCB_PATH_MAX];
    tcb_error e = {0};
    tcb_cell_result c;
    if (tcb_cell_path(path, sizeof path, run_dir, t->d->name, t->s->name, t->m->label, t->seed, &e) ||
        !tcb_is_file(path)) {
        snprintf(row->note, sizeof row->note, "no cell file yet");
        return;
    }
    if (tcb_cell_load(path, &c, &e)) {
        snprintf(row->note, sizeof row->note, "%.200s", e.msg);
        return;
    }
    if (c.status != TCB_CELL_OK)
        snprintf(row->note, sizeof row->note, "the cell is %s", tcb_cell_status_name(c.status));
    else if (k >= c.n_pairs)
        snprintf(row->note, sizeof row->note, "the cell has %d pairs", c.n_pairs);
    else
        row->found = 1, row->rec = c.pairs[k];
    tcb_cell_free(&c);
}

/* The cell file's pair with the largest m_sL2: where to look first. */
static int worst_pair(const char *run_dir, const target *t, int *k, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    tcb_cell_result c;
    int rc = tcb_cell_path(path, sizeof path, run_dir, t->d->name, t->s->name, t->m->label,
                           t->seed, err);
    if (!rc) rc = tcb_cell_load(path, &c, err);
    if (rc) return rc;
    if (c.status != TCB_CELL_OK || c.n_pairs == 0)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: the cell has no pairs to choose the worst from", path);
    *k = 0;
    for (int p = 1; p < c.n_pairs; p++)
        if (c.pairs[p].sl2.mean > c.pairs[*k].sl2.mean) *k = p;
    tcb_cell_free(&c);
    return rc;
}

/* Largest relative difference between the recomputed metrics and the
 * file's; frames that differ count as 1. The geodesic ones count when the
 * file has them (not in a cell written before them). */
static double row_difference(const tcb_pair_capture *cap, const tcb_pair_record *r)
{
    if (cap->i != r->i || cap->j != r->j) return 1;
    const tcb_pair_metrics *m = &cap->metrics;
    const double a[6] = {m->sl2.mean, m->rank.mean, m->auc, cap->cd, m->geo.mean, m->geo_auc};
    const double b[6] = {r->sl2.mean, r->rank.mean, r->auc, r->cd, r->geo.mean, r->geo_auc};
    double worst = 0;
    for (int k = 0; k < (r->geo.n > 0 ? 6 : 4); k++) {
        if (isnan(a[k]) || isnan(b[k])) {
            if (isnan(a[k]) != isnan(b[k])) return 1;
            continue;
        }
        double d = fabs(a[k] - b[k]) / fmax(fabs(b[k]), 1e-12);
        worst = d > worst ? d : worst;
    }
    return worst;
}

static int write_recon(const char *dir, const char *name, const tcb_sequence *seq, int frame,
                       const float *pts, int n, const uint8_t *rgb_pos, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int32_t *near = malloc((size_t)n * sizeof *near);
    uint8_t *rgb = malloc((size_t)n * 3);
    int rc = !near || !rgb ? tcb_fail(err, TCB_ERR_NOMEM, "out of memory") : TCB_OK;
    if (!rc) rc = tcb_project_to_vertices(tcb_seq_frame(seq, frame), seq->n_verts, pts, n, near, err);
    if (!rc) {
        for (int k = 0; k < n; k++) memcpy(rgb + 3 * (size_t)k, rgb_pos + 3 * (size_t)near[k], 3);
        rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, name);
    }
    if (!rc) rc = tcb_ply_write(path, pts, n, NULL, 0, rgb, err);
    free(near);
    free(rgb);
    return rc;
}

static int write_vertices_csv(const char *dir, const tcb_pair_capture *cap, const double *verr,
                              int nv, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    tcb_atomic_file af;
    int rc = tcb_path_join(path, sizeof path, err, "%s/vertices.csv", dir);
    if (!rc) rc = tcb_atomic_open(&af, path, err);
    if (rc) return rc;
    fprintf(af.fp, "vertex,predicted,error,geodesic\n");
    for (int k = 0; k < nv; k++)
        fprintf(af.fp, "%d,%d,%.9g,%.9g\n", k, cap->pred[k], verr[k], cap->geo[k]);
    return tcb_atomic_commit(&af, err);
}

/* A number, or null when not finite (no CD) or absent (`has` 0: no
 * geodesic error in an older cell file). */
static void add_value(cJSON *o, const char *key, int has, double x)
{
    if (!has || isnan(x)) cJSON_AddNullToObject(o, key);
    else cJSON_AddNumberToObject(o, key, x);
}

static cJSON *metrics_json(const tcb_pair_metrics *m, double cd)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "sl2", m->sl2.mean);
    cJSON_AddNumberToObject(o, "rank", m->rank.mean);
    cJSON_AddNumberToObject(o, "auc", m->auc);
    add_value(o, "cd", 1, cd);
    add_value(o, "geo", m->geo.n > 0, m->geo.mean);
    add_value(o, "geo_auc", m->geo.n > 0, m->geo_auc);
    add_value(o, "geo_unreachable", m->geo.n > 0, m->geo_unreachable);
    return o;
}

/* The cell file's row in the shape of the recomputed metrics. */
static tcb_pair_metrics record_metrics(const tcb_pair_record *r)
{
    tcb_pair_metrics m = {.sl2 = r->sl2, .sl2sq = r->sl2sq, .rank = r->rank, .auc = r->auc,
                          .geo = r->geo, .geo_auc = r->geo_auc,
                          .geo_unreachable = r->geo_unreachable};
    return m;
}

static int write_pair_json(const char *dir, const target *t, int k, const tcb_pair_capture *cap,
                           const cell_row *row, double diff, double area, tcb_error *err)
{
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "format", "tcbench-inspect/1");
    cJSON_AddStringToObject(j, "dataset", t->d->name);
    cJSON_AddStringToObject(j, "sequence", t->s->name);
    cJSON_AddStringToObject(j, "method", t->m->label);
    cJSON_AddNumberToObject(j, "seed", t->seed);
    cJSON_AddNumberToObject(j, "pair", k);
    cJSON_AddNumberToObject(j, "i", cap->i);
    cJSON_AddNumberToObject(j, "j", cap->j);
    cJSON_AddNumberToObject(j, "target_area", area);
    cJSON_AddItemToObject(j, "recomputed", metrics_json(&cap->metrics, cap->cd));
    if (row->found) {
        tcb_pair_metrics m = record_metrics(&row->rec);
        cJSON_AddItemToObject(j, "cell", metrics_json(&m, row->rec.cd));
        cJSON_AddNumberToObject(j, "max_relative_difference", diff);
    } else {
        cJSON_AddNullToObject(j, "cell");
        cJSON_AddStringToObject(j, "cell_note", row->note);
    }
    cJSON_AddStringToObject(j, "units", "normalized coordinates; sl2 Euclidean, rank and auc fractions, cd "
                                        "squared; geo the geodesic error over sqrt(target_area), geo_auc "
                                        "a fraction, geo_unreachable a vertex count");
    cJSON_AddStringToObject(j, "colours",
                            "source/target/transfer: xyz of the first frame -> rgb; error: viridis "
                            "from 0 to sqrt(0.02); recon: colour of the nearest GT vertex");
    char path[TCB_PATH_MAX];
    int rc = tcb_path_join(path, sizeof path, err, "%s/pair.json", dir);
    if (!rc) rc = tcb_json_save(path, j, err);
    cJSON_Delete(j);
    return rc;
}

static int write_mesh(const char *dir, const char *name, const tcb_sequence *seq,
                      const float *verts, const uint8_t *rgb, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, name);
    return rc ? rc : tcb_ply_write(path, verts, seq->n_verts, seq->faces, seq->n_faces, rgb, err);
}

/* source, target, transfer and error side by side in pair.png. */
static int write_picture(const char *dir, const tcb_sequence *seq, const tcb_pair_capture *cap,
                         const uint8_t *pos, const uint8_t *moved, const uint8_t *errc,
                         tcb_error *err)
{
    char path[TCB_PATH_MAX], t_src[64], t_dst[64], t_mov[64];
    snprintf(t_src, sizeof t_src, "source: frame %d", cap->i);
    snprintf(t_dst, sizeof t_dst, "target: frame %d", cap->j);
    snprintf(t_mov, sizeof t_mov, "transfer %d -> %d", cap->i, cap->j);
    const float *vi = tcb_seq_frame(seq, cap->i), *vj = tcb_seq_frame(seq, cap->j);
    const tcb_render_panel panels[] = {
        {t_src, vi, pos, NULL}, {t_dst, vj, pos, NULL}, {t_mov, vj, moved, NULL},
        {"error |q_pred - q|", vj, errc, NULL}};
    int rc = tcb_path_join(path, sizeof path, err, "%s/pair.png", dir);
    return rc ? rc
              : tcb_render_panels(path, panels, 4, seq->n_verts, seq->faces, seq->n_faces,
                                  tcb_seq_frame(seq, 0), seq->n_verts, sqrt(TCB_PCK_MAX), err);
}

/* Every file of tcb/inspect.h into dir. */
static int write_files(const char *dir, const tcb_sequence *seq, const target *t, int k,
                       const tcb_pair_capture *cap, const cell_row *row, double diff,
                       const double *verr, tcb_error *err)
{
    size_t nv = (size_t)seq->n_verts;
    uint8_t *pos = malloc(nv * 3), *moved = malloc(nv * 3), *errc = malloc(nv * 3);
    int rc = !pos || !moved || !errc ? tcb_fail(err, TCB_ERR_NOMEM, "out of memory")
                                     : tcb_mkdirs(dir, err);
    if (!rc) {
        tcb_color_by_position(tcb_seq_frame(seq, 0), seq->n_verts, pos);
        for (size_t v = 0; v < nv; v++) {
            memcpy(moved + 3 * v, pos + 3 * (size_t)cap->pred[v], 3);
            tcb_color_by_error(verr[v], sqrt(TCB_PCK_MAX), errc + 3 * v);
        }
    }
    const float *vi = tcb_seq_frame(seq, cap->i), *vj = tcb_seq_frame(seq, cap->j);
    if (!rc) rc = write_mesh(dir, "source.ply", seq, vi, pos, err);
    if (!rc) rc = write_mesh(dir, "target.ply", seq, vj, pos, err);
    if (!rc) rc = write_mesh(dir, "transfer.ply", seq, vj, moved, err);
    if (!rc) rc = write_mesh(dir, "error.ply", seq, vj, errc, err);
    if (!rc && cap->recon[0])
        rc = write_recon(dir, "recon_i.ply", seq, cap->i, cap->recon[0], cap->n_recon[0], pos, err);
    if (!rc && cap->recon[1])
        rc = write_recon(dir, "recon_j.ply", seq, cap->j, cap->recon[1], cap->n_recon[1], pos, err);
    if (!rc) rc = write_picture(dir, seq, cap, pos, moved, errc, err);
    if (!rc) rc = write_vertices_csv(dir, cap, verr, seq->n_verts, err);
    if (!rc) rc = write_pair_json(dir, t, k, cap, row, diff, seq->areas[cap->j], err);
    free(pos);
    free(moved);
    free(errc);
    return rc;
}

/* "  m_sL2 …  CD …  m_geo …  AUC_geo …" in table units; "-" for a missing
 * CD or geodesic error. */
static void print_metrics(FILE *out, const char *what, const tcb_pair_metrics *m, double cd)
{
    fprintf(out, "  %-10s  m_sL2 %8.2f  rank %6.2f  AUC %6.2f  CD ", what, 1e3 * m->sl2.mean,
            1e2 * m->rank.mean, 1e2 * m->auc);
    if (isnan(cd)) fprintf(out, "%7s", "-");
    else fprintf(out, "%7.3f", 1e3 * cd);
    if (m->geo.n > 0)
        fprintf(out, "  m_geo %8.2f  AUC_geo %6.2f", 1e3 * m->geo.mean, 1e2 * m->geo_auc);
    else
        fprintf(out, "  m_geo %8s  AUC_geo %6s", "-", "-");
}

static void print_account(FILE *out, const target *t, int k, const tcb_pair_capture *cap,
                          const cell_row *row, double diff, const double *verr, int nv)
{
    if (!out) return;
    fprintf(out, "%s/%s %s seed %d, pair %d: frame %d -> frame %d\n", t->d->name, t->s->name,
            t->m->label, t->seed, k, cap->i, cap->j);
    print_metrics(out, "recomputed", &cap->metrics, cap->cd);
    fputc('\n', out);
    if (row->found) {
        tcb_pair_metrics m = record_metrics(&row->rec);
        print_metrics(out, "cell file", &m, row->rec.cd);
        fprintf(out, "  (%s: largest relative difference %.1e)\n", diff <= 1e-6 ? "agree" : "DIFFER",
                diff);
    } else {
        fprintf(out, "  cell file   not compared: %s\n", row->note);
    }
    int worst = 0, beyond = 0;
    double cut = sqrt(TCB_PCK_MAX);
    for (int v = 0; v < nv; v++) {
        if (verr[v] > verr[worst]) worst = v;
        beyond += verr[v] > cut;
    }
    fprintf(out, "  vertices beyond the PCK range (error > %.4f): %d of %d (%.1f %%); worst: "
                 "vertex %d -> %d, error %.4f\n",
            cut, beyond, nv, 100.0 * beyond / nv, worst, cap->pred[worst], verr[worst]);
    if (cap->metrics.geo_unreachable > 0)
        fprintf(out, "  geodesic: %d vertices predicted on another piece of the mesh, scored by "
                     "the straight line\n",
                cap->metrics.geo_unreachable);
}

/* Evaluates pair *k (resolved from "worst" when < 0) of the opened cell
 * into cap. */
static int recompute(const tcb_config *cfg, const tcb_inspect_opts *o, const target *t, int *k,
                     tcb_cell_session *ses, tcb_pair_capture *cap, tcb_error *err)
{
    int rc = *k < 0 ? worst_pair(o->run_dir, t, k, err) : TCB_OK;
    if (!rc) rc = tcb_cell_session_open(cfg, o->run_dir, t, o->threads, o->reporter, ses, err);
    return rc ? rc : tcb_cell_eval_pair(&ses->job, *k, cap, err);
}

int tcb_inspect(const tcb_inspect_opts *o, FILE *out, char *out_path, tcb_error *err)
{
    char dir[TCB_PATH_MAX];
    tcb_config cfg;
    int rc = tcb_run_config_open(o->run_dir, &cfg, err);
    if (rc) return rc;
    target t = {0};
    tcb_cell_session ses = {0};
    tcb_pair_capture cap = {0};
    double *verr = NULL;
    int k = o->pair;
    rc = tcb_cell_target_resolve(&cfg, o->method, o->seed, o->sequence, &t, err);
    if (!rc) rc = recompute(&cfg, o, &t, &k, &ses, &cap, err);
    if (!rc && o->out_dir) rc = tcb_path_join(dir, sizeof dir, err, "%s", o->out_dir);
    else if (!rc)
        rc = tcb_path_join(dir, sizeof dir, err, "%s/inspect/%s/%s/%s/seed_%d/pair_%d", o->run_dir,
                           t.d->name, t.s->name, t.m->label, t.seed, k);
    if (!rc && !(verr = malloc((size_t)ses.seq.n_verts * sizeof *verr)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    /* Each vertex's error as the metrics compute it (their sL2 is its mean). */
    if (!rc) rc = tcb_pair_vertex_metrics(tcb_seq_frame(&ses.seq, cap.j), ses.seq.n_verts, cap.pred, verr, NULL, err);
    if (!rc) {
        for (int v = 0; v < ses.seq.n_verts; v++) verr[v] = sqrt(verr[v]);
        cell_row row;
        load_cell_row(o->run_dir, &t, k, &row);
        double diff = row.found ? row_difference(&cap, &row.rec) : 0;
        rc = write_files(dir, &ses.seq, &t, k, &cap, &row, diff, verr, err);
        if (!rc) print_account(out, &t, k, &cap, &row, diff, verr, ses.seq.n_verts);
        if (!rc && out_path) snprintf(out_path, TCB_PATH_MAX, "%s", dir);
    }
    free(verr);
    tcb_pair_capture_free(&cap);
    tcb_cell_session_close(&ses);
    tcb_config_free(&cfg);
    return rc;
}

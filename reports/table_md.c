/* Markdown tables shaped like the paper's: a block per sequence (with its
 * cells seed by seed when a method ran several), a MEAN block per dataset
 * over its test sequences. */
#include <math.h>
#include <string.h>

#include "reports/chart.h"
#include "reports/writers.h"

static void pairs_text(const tcb_rpt_block *b, char *out, size_t size)
{
    if (b->n_pairs_min == b->n_pairs_max)
        snprintf(out, size, "%d", b->n_pairs_min);
    else
        snprintf(out, size, "%d–%d", b->n_pairs_min, b->n_pairs_max);
}

/* " (seeds 0, 2)" after a method that ran on fewer of the block's seeds than
 * the others: its pooled numbers then rest on fewer seeds than the heading
 * says. Empty otherwise. */
static void fewer_seeds_note(const tcb_rpt_block *b, const tcb_rpt_row *r, char *out, size_t size)
{
    out[0] = '\0';
    if (r->n_by_seed == 0 || r->n_by_seed >= b->n_seed_list) return;
    size_t used = (size_t)snprintf(out, size, " (seed%s", r->n_by_seed > 1 ? "s" : "");
    for (int i = 0; i < r->n_by_seed && used < size; i++)
        used += (size_t)snprintf(out + used, size - used, "%s %d", i ? "," : "", r->by_seed[i].seed);
    if (used < size) snprintf(out + used, size - used, ")");
}

/* Rows whose geodesic error scored some vertices by the straight line
 * (their prediction on another piece of the mesh): how many, so a reader
 * knows how much of m_geo is not a path. */
static void write_unreachable_note(FILE *f, const tcb_rpt_block *b)
{
    int header = 0;
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        if (!r->has[TCB_M_GEO] || r->geo_unreachable <= 0) continue;
        if (!header++)
            fprintf(f, "\nm_geo: vertices predicted on another connected piece of the mesh, "
                       "scored by their straight-line distance (docs/protocol.md):\n");
        fprintf(f, "- %s: %.0f of %.0f vertices (%.2f %%)\n", r->method, r->geo_unreachable,
                r->geo_vertices, 100.0 * r->geo_unreachable / r->geo_vertices);
    }
}

/* Which methods took normals with their input points (the config's
 * "input_normals", or their own estimate), and that the others took
 * points only: a comparison of the two kinds should say so. */
static void write_normals_note(FILE *f, const tcb_rpt_block *b)
{
    int with = 0;
    for (int k = 0; k < b->n_rows; k++) with += b->rows[k].normals[0] != '\0';
    if (!with) return;
    fprintf(f, "\nNormals with the input points: ");
    for (int k = 0, i = 0; k < b->n_rows; k++)
        if (b->rows[k].normals[0]) fprintf(f, "%s%s (%s)", i++ ? ", " : "", b->rows[k].method, b->rows[k].normals);
    fprintf(f, with < b->n_rows ? "; the other methods took points only.\n" : ".\n");
}

/* A sequence of points alone: its geodesic and reconstruction columns are
 * missing because they do not apply, not because a method failed them. */
static void write_faces_note(FILE *f, const tcb_rpt_block *b)
{
    if (!b->n_rows) return;
    for (int k = 0; k < b->n_rows; k++)
        if (!b->rows[k].no_faces) return;
    fprintf(f, "\nNot applicable: the geodesic error (m_geo, AUC_geo) and the reconstruction metrics (CD-L2, "
               "NC, F-score): %s no faces, points alone (docs/datasets.md, \"pcl_seq\"); CD is measured "
               "against those points.\n",
            strcmp(b->role, "mean") ? "the sequence has" : "the test sequences have");
}

/* atlasnet and mca rows with the same params whose m_sL2 agree within 1 %:
 * a reader takes that for a bug (one method run twice) unless told why.
 * The two start from the same weights and draw the same batches (the
 * seed's streams "atlas/init" and "atlas/train", methods/atlas/), so they
 * part only as fast as mca's metric-consistency term moves the weights. */
static void write_twin_note(FILE *f, const tcb_rpt_block *b)
{
    for (int k = 0; k < b->n_rows; k++)
        for (int l = 0; l < b->n_rows; l++) {
            const tcb_rpt_row *a = &b->rows[k], *m = &b->rows[l];
            if (strcmp(a->method_impl, "atlasnet") || strcmp(m->method_impl, "mca") || strcmp(a->status, "ok") ||
                strcmp(m->status, "ok") || !a->params[0] || strcmp(a->params, m->params))
                continue;
            double x = a->mean[TCB_M_SL2], y = m->mean[TCB_M_SL2];
            if (fabs(x - y) > 0.01 * fmax(x, y)) continue;
            fprintf(f,
                    "\n%s and %s agree on m_sL2 (%.2f and %.2f): with the same params (%s) they start from "
                    "the same weights and train on the same batches (the seed's streams), and differ only by "
                    "mca's metric-consistency term (α_mc · L_mc, from the first iteration, no warm-up), whose "
                    "effect on the weights grows with the training: a short one leaves it no time to act (README, "
                    "\"atlasnet and mca in the default benchmark\"). The paper reports them apart after its full "
                    "training (preset paper: 200,000 iterations).\n",
                    a->method, m->method, x, y, a->params);
        }
}

/* What bold and ≈ mean under a table with statistics, and what its
 * intervals rest on (docs/protocol.md, "Statistics of a comparison"). */
static void write_marks_legend(FILE *f, const tcb_rpt_block *b)
{
    if (!b->compared) return;
    fprintf(f, "\n**bold**: best, significantly better than every other method (Holm-adjusted Wilcoxon p < "
               "0.05 over this table's comparisons of the column, and the 95 %% bootstrap interval of the "
               "difference excludes 0); ≈: tied for best (the leader and every method not significantly worse "
               "than it). Differences, intervals and p-values: comparisons.md.");
    int single = 0;
    for (int k = 0; k < b->n_rows; k++) single |= b->rows[k].n_seeds == 1 && !strcmp(b->rows[k].status, "ok");
    if (!strcmp(b->role, "mean")) {
        int n = 0;
        for (int k = 0; k < b->n_cmp && !n; k++)
            for (int m = 0; m < TCB_N_METRICS && !n; m++) n = b->cmp[k].c.m[m].has ? b->cmp[k].c.n : 0;
        if (n)
            fprintf(f, " Here the test sequences (%d) are resampled%s.", n,
                    n < 10 ? ": so few that the intervals are rough (a 95 % interval covers about 80 % with 4 "
                             "sequences, 90 % with 10) and Wilcoxon needs 6 to reach p < 0.05"
                           : "");
    } else if (single) {
        fprintf(f, " A method with one seed: its intervals cover the sampling of pairs only, not the training "
                   "variance.");
    }
    fprintf(f, "\n");
}

static void write_table(FILE *f, const tcb_rpt_block *b, const unsigned char *shown)
{
    fprintf(f, "| method |");
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (shown[m]) fprintf(f, " %s |", tcb_rpt_metrics[m].label);
    fprintf(f, "\n|:---|");
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (shown[m]) fprintf(f, "---:|");
    fprintf(f, "\n");
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        char note[128];
        fewer_seeds_note(b, r, note, sizeof note);
        fprintf(f, "| %s%s |", r->method, note);
        for (int m = 0; m < TCB_N_METRICS; m++) {
            if (!shown[m]) continue;
            char cell[128];
            tcb_rpt_cell_text(r, m, " ± ", cell, sizeof cell);
            const char *em = r->best[m] ? "**" : strcmp(r->status, "ok") ? "*" : "";
            fprintf(f, " %s%s%s%s |", em, cell, em, r->tie[m] ? " ≈" : "");
        }
        fprintf(f, "\n");
    }
    int header = 0;
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        if (!strcmp(r->status, "ok")) continue;
        if (!header++) fprintf(f, "\nNot ok:\n");
        fprintf(f, "- %s: %s — %s\n", r->method, r->status_text, r->message);
    }
    write_marks_legend(f, b);
    write_normals_note(f, b);
    write_faces_note(f, b);
    write_unreachable_note(f, b);
    write_twin_note(f, b);
    fprintf(f, "\n");
}

/* A seed's value: "12.34", bold when best among the block's cells of that
 * seed, "-" or the cell's status like the pooled table. */
static void seed_cell(const tcb_rpt_seed *s, int m, char *out, size_t size)
{
    const tcb_rpt_metric_def *d = &tcb_rpt_metrics[m];
    if (strcmp(s->status, "ok"))
        snprintf(out, size, "*%s*", s->status);
    else if (!s->has[m])
        snprintf(out, size, "-");
    else
        snprintf(out, size, "%s%.*f%s", s->best[m] ? "**" : "", d->decimals, s->mean[m],
                 s->best[m] ? "**" : "");
}

/* Each cell's means, grouped by seed, best per seed in bold: whether the
 * ranking of the pooled table holds seed by seed. */
static void write_seed_table(FILE *f, const tcb_rpt_block *b, const unsigned char *shown)
{
    int several = 0;
    for (int k = 0; k < b->n_rows; k++) several |= b->rows[k].n_by_seed > 1;
    if (!several) return;
    fprintf(f, "Per seed (each cell's means; best per seed in **bold** by its value alone, untested: which "
               "differences are real, the table above and comparisons.md say):\n\n| seed | method |");
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (shown[m]) fprintf(f, " %s |", tcb_rpt_metrics[m].label);
    fprintf(f, "\n|---:|:---|");
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (shown[m]) fprintf(f, "---:|");
    fprintf(f, "\n");
    for (int d = 0; d < b->n_seed_list; d++)
        for (int k = 0; k < b->n_rows; k++)
            for (int i = 0; i < b->rows[k].n_by_seed; i++) {
                const tcb_rpt_seed *s = &b->rows[k].by_seed[i];
                if (s->seed != b->seed_list[d]) continue;
                fprintf(f, "| %d | %s |", s->seed, b->rows[k].method);
                for (int m = 0; m < TCB_N_METRICS; m++) {
                    if (!shown[m]) continue;
                    char cell[64];
                    seed_cell(s, m, cell, sizeof cell);
                    fprintf(f, " %s |", cell);
                }
                fprintf(f, "\n");
            }
    fprintf(f, "\n");
}

/* The block's plots, written beside tables.md by the report. */
static void write_plot_links(FILE *f, const tcb_rpt_block *b)
{
    char pck[1024], geo[1024], gap[1024];
    tcb_error err = {0};
    if (tcb_chart_file_name(b, "pck", pck, sizeof pck, &err) ||
        tcb_chart_file_name(b, "pck_geo", geo, sizeof geo, &err) ||
        tcb_chart_file_name(b, "gap", gap, sizeof gap, &err))
        return; /* a name too long for a link: the plots are still in the directory */
    fprintf(f, "![PCK curves](%s) ![geodesic PCK curves](%s) ![m_sL2 by frame distance](%s)\n\n",
            pck, geo, gap);
}

static void write_dataset(FILE *f, const tcb_rpt *r, const tcb_rpt_dataset *d)
{
    unsigned char shown[TCB_N_METRICS];
    for (int m = 0; m < TCB_N_METRICS; m++) shown[m] = (unsigned char)tcb_rpt_dataset_shows(r, d, m);
    fprintf(f, "## %s\n\n", d->name);
    for (int k = d->first; k < d->first + d->n; k++) {
        const tcb_rpt_block *b = &r->blocks[k];
        char pairs[64];
        pairs_text(b, pairs, sizeof pairs);
        fprintf(f, "### %s / %s\n\nrole: %s · pairs: %s · seeds: %s\n\n", d->name, b->sequence,
                b->role, pairs, b->seeds);
        write_table(f, b, shown);
        write_seed_table(f, b, shown);
        if (b->n_pairs_max > 0) write_plot_links(f, b);
    }
    if (!d->n_test) {
        fprintf(f, "### %s / MEAN\n\nNo test sequence in this run: no MEAN block.\n\n", d->name);
        return;
    }
    fprintf(f,
            "### %s / MEAN\n\nmean over the %d test sequence%s (%s) of the per-sequence means, "
            "and separately of the per-sequence stds\n\n",
            d->name, d->n_test, d->n_test == 1 ? "" : "s", d->test_sequences);
    write_table(f, &d->mean, shown);
}

void tcb_rpt_write_md(FILE *f, const tcb_rpt *r)
{
    fprintf(f, "# tcbench results\n\n"
               "m_sL2 ×1e3, rank %%, AUC %%, CD ×1e3, as mean ± std (m_sL2 and rank over all "
               "vertices of all pairs, AUC and CD over pairs; seeds pooled). Best per column in "
               "**bold** only when significantly better than every other method, else the leaders tied "
               "for best marked ≈ (the legend under each table); \"-\": the method has no reconstruction. Beside the paper's metrics, "
               "the geodesic error (docs/protocol.md): m_geo ×1e3 (path length on the target "
               "mesh over sqrt(its area), over all vertices of all pairs) and AUC_geo %% (its "
               "PCK up to 0.25, over pairs); \"-\" there: cells scored before it existed. Corr ×1e3: the "
               "clip protocol's tracking error, over clips; Corr-mesh ×1e3: the same as DynoSurf's script "
               "computes it, from the method's surfaces of one topology (docs/protocol.md). A column no "
               "method of a dataset has is left out. CD-L2 ×1e5 (as the papers), NC %% and F-score %% at 0.5 %% and "
               "1 %% (F@0.5%%, F@1%%): the reconstruction metrics of DynoSurf's evaluation, over the "
               "evaluated frames; \"-\" there: the method gives no surface (or its cells predate them).\n\n");
    tcb_rpt_write_presets_md(f, r);
    for (int k = 0; k < r->n_datasets; k++) write_dataset(f, r, &r->datasets[k]);
}

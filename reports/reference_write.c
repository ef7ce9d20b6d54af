/* `tcbench report RUN --reference NAME`: each reference table the run
 * reproduces, in the paper's shape, our value beside the paper's and
 * ours/paper per cell, with a line per metric saying whether the methods
 * come out in the paper's order; as Markdown, LaTeX (booktabs) and CSV. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "reports/reference.h"
#include "reports/writers.h"
#include "tcb/config.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"
#include "tcb/report.h"

static void ours_text(const tcb_ref_cmp_row *row, int m, const char *pm, char *out, size_t size)
{
    if (!row->ours) snprintf(out, size, "not run");
    else tcb_rpt_cell_text(row->ours, m, pm, out, size);
}

static void paper_text(const tcb_ref_row *p, int m, const char *pm, char *out, size_t size)
{
    int d = tcb_rpt_metrics[m].decimals;
    if (!p->has[m]) snprintf(out, size, "-");
    else if (!p->has_std[m]) snprintf(out, size, "%.*f", d, p->mean[m]);
    else snprintf(out, size, "%.*f%s%.*f", d, p->mean[m], pm, d, p->std[m]);
}

/* far_mark follows a ratio beyond TCB_REF_FAR ("†" or LaTeX's dagger). */
static void ratio_text(const tcb_ref_cmp_row *row, int m, const char *far_mark, char *out, size_t size)
{
    double q = tcb_ref_ratio(row, m);
    if (!isnan(q)) snprintf(out, size, "%.2f%s", q, tcb_ref_far(row, m) ? far_mark : "");
    else snprintf(out, size, "-");
}

/* A value's three texts: ours, the paper's, ours/paper; pm joins mean and std. */
typedef struct value_texts {
    char ours[96], paper[96], ratio[32];
} value_texts;

/* The marks of Markdown and LaTeX: plus-minus and the far ratio's. */
typedef struct text_marks {
    const char *pm, *far;
} text_marks;

static const text_marks md_marks = {" ± ", " †"}, tex_marks = {" $\\pm$ ", "$^\\dagger$"};

static void value_texts_of(const tcb_ref_cmp_row *row, int m, const text_marks *marks, value_texts *t)
{
    ours_text(row, m, marks->pm, t->ours, sizeof t->ours);
    paper_text(row->paper, m, marks->pm, t->paper, sizeof t->paper);
    ratio_text(row, m, marks->far, t->ratio, sizeof t->ratio);
}

static const char *order_name(tcb_ref_order o)
{
    return o == TCB_REF_AGREES ? "agrees" : o == TCB_REF_FLIPS_SIGNIFICANT ? "flips (significant)"
                                                                          : "flips (within noise)";
}

/* "- m_sL2 ↓: agrees (3 orderings)", or a count per kind and a line per
 * ordering the paper makes (row better in the paper first): agrees,
 * flips (significant) or flips (within noise) (reference.h). */
static void md_orderings(FILE *f, const tcb_ref_group *g, int m)
{
    int count[4] = {0}, better;
    for (int i = 0; i < g->n_rows; i++)
        for (int j = i + 1; j < g->n_rows; j++) count[tcb_ref_order_of(g, i, j, m, &better)]++;
    int n = count[TCB_REF_AGREES] + count[TCB_REF_FLIPS_SIGNIFICANT] + count[TCB_REF_FLIPS_NOISE];
    const char *name = tcb_rpt_metrics[m].label;
    if (!n) {
        fprintf(f, "- %s: nothing to order\n", name);
        return;
    }
    if (count[TCB_REF_AGREES] == n) {
        fprintf(f, "- %s: agrees (%d ordering%s)\n", name, n, n == 1 ? "" : "s");
        return;
    }
    fprintf(f, "- %s: %d ordering%s: agrees %d, flips (significant) %d, flips (within noise) %d\n", name, n,
            n == 1 ? "" : "s", count[TCB_REF_AGREES], count[TCB_REF_FLIPS_SIGNIFICANT], count[TCB_REF_FLIPS_NOISE]);
    for (int i = 0; i < g->n_rows; i++)
        for (int j = i + 1; j < g->n_rows; j++) {
            tcb_ref_order o = tcb_ref_order_of(g, i, j, m, &better);
            if (o == TCB_REF_UNORDERED) continue;
            fprintf(f, "  - the paper has %s better than %s: %s\n", g->rows[better].paper->paper_row,
                    g->rows[better == i ? j : i].paper->paper_row, order_name(o));
        }
}

/* ---- Markdown ---------------------------------------------------------- */

static void md_group(FILE *f, const tcb_ref_cmp_table *t, const tcb_ref_group *g)
{
    fprintf(f, "\n**%s / %s**\n\n| paper row | cell |", g->dataset, g->sequence);
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (t->shown[m]) fprintf(f, " %s ours | paper | ours/paper |", tcb_rpt_metrics[m].label);
    fprintf(f, "\n|:---|:---|");
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (t->shown[m]) fprintf(f, "---:|---:|---:|");
    fprintf(f, "\n");
    for (int k = 0; k < g->n_rows; k++) {
        const tcb_ref_cmp_row *row = &g->rows[k];
        fprintf(f, "| %s | %s |", row->paper->paper_row, row->paper->method);
        for (int m = 0; m < TCB_N_METRICS; m++) {
            value_texts v;
            if (!t->shown[m]) continue;
            value_texts_of(row, m, &md_marks, &v);
            fprintf(f, " %s | %s | %s |", v.ours, v.paper, v.ratio);
        }
        fprintf(f, "\n");
    }
    fprintf(f, "\n†: ours beyond %.1f× the paper's, either way (a ratio above %.2f or below %.2f).\n",
            TCB_REF_FAR, TCB_REF_FAR, 1 / TCB_REF_FAR);
    fprintf(f, "\nThe order of the rows, here and in the paper (a flip is significant when our difference "
               "is: Holm-adjusted Wilcoxon p < 0.05 and its 95 %% interval excluding 0, comparisons.md):\n\n");
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (t->shown[m]) md_orderings(f, g, m);
}

/* A row of block blk is in the paper when a row of these tables names it,
 * or names its method in its dataset's MEAN (the paper's row pools it). */
static int row_in_paper(const tcb_ref_cmp *c, const tcb_rpt_block *blk, const tcb_rpt_row *row)
{
    for (int k = 0; k < c->n_tables; k++)
        for (int g = 0; g < c->tables[k].n_groups; g++) {
            const tcb_ref_group *gr = &c->tables[k].groups[g];
            int pooled = !strcmp(gr->sequence, "MEAN") && !strcmp(gr->dataset, blk->dataset);
            for (int r = 0; r < gr->n_rows; r++) {
                const tcb_rpt_row *ours = gr->rows[r].ours;
                if (ours == row || (pooled && ours && !strcmp(ours->method, row->method))) return 1;
            }
        }
    return 0;
}

/* The run's cells that no row of these tables names (a method the paper
 * did not run, a sequence it did not report), so that a reader looks for
 * them in tables.md rather than taking them as left out. */
static void md_not_in_paper(FILE *f, const tcb_ref_cmp *c)
{
    int any = 0;
    for (int b = 0; b < c->run->n_blocks; b++) {
        const tcb_rpt_block *blk = &c->run->blocks[b];
        int first = 1;
        for (int r = 0; r < blk->n_rows; r++) {
            if (row_in_paper(c, blk, &blk->rows[r])) continue;
            if (!any) fprintf(f, "\nIn the run but in no row of these tables (tables.md has them):\n\n");
            if (first) fprintf(f, "- %s / %s: ", blk->dataset, blk->sequence);
            fprintf(f, "%s%s", first ? "" : ", ", blk->rows[r].method);
            any = 1, first = 0;
        }
        if (!first) fprintf(f, "\n");
    }
}

static void write_md(FILE *f, const tcb_ref_cmp *c)
{
    fprintf(f, "# Beside the paper: %s\n\n%s\n\n", c->ref->name, c->ref->paper);
    tcb_rpt_write_presets_md(f, c->run);
    for (int k = 0; k < c->n_tables; k++) {
        const tcb_ref_cmp_table *t = &c->tables[k];
        fprintf(f, "\n## %s\n", t->table->title);
        for (int g = 0; g < t->n_groups; g++) md_group(f, t, &t->groups[g]);
        if (t->n_absent) fprintf(f, "\n%d more group%s of this table not in the run.\n", t->n_absent,
                                 t->n_absent == 1 ? "" : "s");
    }
    md_not_in_paper(f, c);
}

/* ---- LaTeX ------------------------------------------------------------- */

static void tex_group(FILE *f, const tcb_ref_cmp_table *t, const tcb_ref_group *g)
{
    int cols = 0;
    for (int m = 0; m < TCB_N_METRICS; m++) cols += t->shown[m];
    fputs("\\begin{table}[t]\n\\centering\n\\caption{", f);
    tcb_rpt_tex_escaped(f, t->table->title);
    fputs(": ", f);
    tcb_rpt_tex_escaped(f, g->dataset);
    fputs("/", f);
    tcb_rpt_tex_escaped(f, g->sequence);
    fprintf(f, ". Each cell: ours / paper (ours$/$paper); $^\\dagger$: ours beyond %.1f$\\times$ the "
               "paper's, either way.}\n\\begin{tabular}{l", TCB_REF_FAR);
    for (int k = 0; k < cols; k++) fputs("c", f);
    fputs("}\n\\toprule\nRow", f);
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (t->shown[m]) fprintf(f, " & %s", tcb_rpt_metrics[m].tex_label);
    fputs(" \\\\\n\\midrule\n", f);
    for (int k = 0; k < g->n_rows; k++) {
        const tcb_ref_cmp_row *row = &g->rows[k];
        tcb_rpt_tex_escaped(f, row->paper->paper_row);
        for (int m = 0; m < TCB_N_METRICS; m++) {
            value_texts v;
            if (!t->shown[m]) continue;
            value_texts_of(row, m, &tex_marks, &v);
            fprintf(f, " & %s / %s (%s)", v.ours, v.paper, v.ratio);
        }
        fputs(" \\\\\n", f);
    }
    fputs("\\bottomrule\n\\end{tabular}\n\\end{table}\n\n", f);
}

static void write_tex(FILE *f, const tcb_ref_cmp *c)
{
    fputs("% tcbench beside the paper; needs \\usepackage{booktabs}.\n\n", f);
    for (int k = 0; k < c->n_tables; k++)
        for (int g = 0; g < c->tables[k].n_groups; g++) tex_group(f, &c->tables[k], &c->tables[k].groups[g]);
}

/* ---- CSV --------------------------------------------------------------- */

static void csv_value(FILE *f, int has, double v)
{
    if (has) fprintf(f, ",%.6g", v);
    else fputs(",", f);
}

static void write_csv(FILE *f, const tcb_ref_cmp *c)
{
    fputs("table,dataset,sequence,paper_row,method,metric,ours_mean,ours_std,paper_mean,paper_std,ratio,status,"
          "beyond_1_5x\n", f);
    for (int k = 0; k < c->n_tables; k++)
        for (int g = 0; g < c->tables[k].n_groups; g++) {
            const tcb_ref_group *gr = &c->tables[k].groups[g];
            for (int r = 0; r < gr->n_rows; r++)
                for (int m = 0; m < TCB_N_METRICS; m++) {
                    const tcb_ref_cmp_row *row = &gr->rows[r];
                    if (!c->tables[k].shown[m]) continue;
                    int ok = row->ours && !strcmp(row->ours->status, "ok") && row->ours->has[m];
                    fprintf(f, "%s,%s,%s,\"%s\",%s,%s", c->tables[k].table->id, gr->dataset, gr->sequence,
                            row->paper->paper_row, row->paper->method, tcb_rpt_metrics[m].key);
                    csv_value(f, ok, ok ? row->ours->mean[m] : 0);
                    csv_value(f, ok, ok ? row->ours->std[m] : 0);
                    csv_value(f, row->paper->has[m], row->paper->mean[m]);
                    csv_value(f, row->paper->has_std[m], row->paper->std[m]);
                    csv_value(f, !isnan(tcb_ref_ratio(row, m)), tcb_ref_ratio(row, m));
                    fprintf(f, ",%s,%d\n", row->ours ? row->ours->status : "not run", tcb_ref_far(row, m));
                }
        }
}

/* ---- the command ------------------------------------------------------- */

/* The tables the run's config says it reproduces of reference `name`
 * (<run>/config.json "reference"); 0 when it names none of it. */
static int config_tables(const char *run_dir, const char *name, char (*ids)[16])
{
    char path[TCB_PATH_MAX];
    cJSON *cfg = NULL;
    tcb_error err = {0};
    if (tcb_path_join(path, sizeof path, &err, "%s/config.json", run_dir) || !tcb_is_file(path) ||
        tcb_json_load(path, &cfg, &err))
        return 0; /* a run without its config: every table naming its cells */
    const cJSON *ref = cJSON_GetObjectItemCaseSensitive(cfg, "reference");
    const cJSON *src = cJSON_GetObjectItemCaseSensitive(ref, "source");
    const cJSON *tables = cJSON_GetObjectItemCaseSensitive(ref, "tables"), *t;
    int n = 0;
    if (cJSON_IsString(src) && !strcmp(src->valuestring, name))
        cJSON_ArrayForEach(t, tables) if (cJSON_IsString(t) && n < TCB_REFERENCE_TABLES_MAX)
            snprintf(ids[n++], sizeof ids[0], "%s", t->valuestring);
    cJSON_Delete(cfg);
    return n;
}

typedef void (*cmp_writer)(FILE *f, const tcb_ref_cmp *c);

static int write_one(const char *dir, const char *name, const char *ext, cmp_writer w, const tcb_ref_cmp *c,
                     tcb_error *err)
{
    char path[TCB_PATH_MAX];
    tcb_atomic_file af;
    int rc = tcb_path_join(path, sizeof path, err, "%s/reference_%s.%s", dir, name, ext);
    if (rc || (rc = tcb_atomic_open(&af, path, err))) return rc;
    w(af.fp, c);
    return tcb_atomic_commit(&af, err);
}

int tcb_report_reference(const char *run_dir, const char *reference, const char *out_dir, FILE *echo,
                         tcb_error *err)
{
    return tcb_report_reference_resampled(run_dir, reference, out_dir, 0, echo, err);
}

int tcb_report_reference_resampled(const char *run_dir, const char *reference, const char *out_dir, int resamples,
                                   FILE *echo, tcb_error *err)
{
    char dir[TCB_PATH_MAX], ids[TCB_REFERENCE_TABLES_MAX][16];
    int rc = out_dir ? tcb_path_join(dir, sizeof dir, err, "%s", out_dir)
                     : tcb_path_join(dir, sizeof dir, err, "%s/report", run_dir);
    tcb_reference ref;
    if (rc || (rc = tcb_reference_load(reference, &ref, err))) return rc;
    tcb_rpt r;
    if ((rc = tcb_rpt_load_compared(run_dir, resamples, &r, err))) {
        tcb_reference_free(&ref);
        return rc;
    }
    tcb_ref_cmp c = {0};
    int n_ids = config_tables(run_dir, ref.name, ids);
    rc = tcb_ref_compare(&ref, &r, (const char(*)[16])ids, n_ids, &c, err);
    if (!rc) rc = tcb_mkdirs(dir, err);
    if (!rc) rc = write_one(dir, ref.name, "md", write_md, &c, err);
    if (!rc) rc = write_one(dir, ref.name, "tex", write_tex, &c, err);
    if (!rc) rc = write_one(dir, ref.name, "csv", write_csv, &c, err);
    if (!rc && echo) write_md(echo, &c);
    if (c.tables) tcb_ref_cmp_free(&c);
    tcb_rpt_free(&r);
    tcb_reference_free(&ref);
    return rc;
}

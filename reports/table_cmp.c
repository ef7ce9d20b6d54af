/* comparisons.md, comparisons.tex, comparisons.csv: per block (sequence or
 * dataset MEAN) and metric, the matrix of pairwise differences row − column
 * with their 95 % bootstrap intervals and Holm-adjusted Wilcoxon p-values
 * (reports/significance.c); significant differences in bold.
 *
 * comparisons.csv: one line per (block, pair of rows a < b, metric), a and
 * b in the table's row order: dataset, sequence, role, metric, method_a,
 * method_b, seeds_a, seeds_b, n (pairs, or sequences when over is
 * "sequences"), over, mean_a, mean_b, diff (a − b), lo, hi, p, p_holm,
 * significant (1/0), resamples, note (why not compared; empty otherwise).
 * Numbers in table units, %.9g; empty where not compared or no test. */
#include <math.h>
#include <string.h>

#include "reports/writers.h"

/* The comparison of rows r and c of b for metric m as seen from r (r − c):
 * NULL when not made; *x filled with the sign turned when needed. */
static const tcb_cmp_metric *seen_from(const tcb_rpt_block *b, int r, int c, int m, tcb_cmp_metric *x)
{
    int flip;
    const tcb_rpt_cmp *p = tcb_rpt_cmp_of(b, r, c, &flip);
    if (!p || !p->c.m[m].has) return NULL;
    *x = p->c.m[m];
    if (flip) {
        double lo = x->lo;
        x->diff = -x->diff, x->lo = -x->hi, x->hi = -lo;
        double t = x->mean_a;
        x->mean_a = x->mean_b, x->mean_b = t;
    }
    return x;
}

/* "-1.234 [-1.50, -0.90] p 0.0012"; "-" when not compared. */
static void cell_text(const tcb_cmp_metric *x, int m, char *out, size_t size)
{
    int d = tcb_rpt_metrics[m].decimals + 1;
    if (!x) snprintf(out, size, "-");
    else if (isnan(x->p_holm)) snprintf(out, size, "%.*f [%.*f, %.*f] no test", d, x->diff, d, x->lo, d, x->hi);
    else snprintf(out, size, "%.*f [%.*f, %.*f] p %.2g", d, x->diff, d, x->lo, d, x->hi, x->p_holm);
}

static int any_compared(const tcb_rpt_block *b, int m)
{
    for (int k = 0; k < b->n_cmp; k++)
        if (!b->cmp[k].note[0] && b->cmp[k].c.m[m].has) return 1;
    return 0;
}

/* The caveats of a block's comparisons, one line each. */
static void block_notes(FILE *f, const tcb_rpt_block *b, const char *bullet)
{
    int single = 0, n = 0;
    for (int k = 0; k < b->n_cmp; k++) {
        if (b->cmp[k].note[0]) fprintf(f, "%s%s vs %s not compared: %s\n", bullet, b->rows[b->cmp[k].a].method,
                                       b->rows[b->cmp[k].b].method, b->cmp[k].note);
        else single |= b->cmp[k].c.single_seed && !b->cmp[k].c.over_sequences, n = b->cmp[k].c.n;
    }
    if (!strcmp(b->role, "mean") && n)
        fprintf(f, "%sover %d test sequence%s, resampled%s\n", bullet, n, n == 1 ? "" : "s",
                n < 10 ? ": so few that the intervals are rough (a 95 % interval covers about 80 % with 4, 90 % "
                         "with 10) and Wilcoxon needs 6 to reach p < 0.05"
                       : "");
    if (single)
        fprintf(f, "%sa method with one seed: its intervals cover the sampling of pairs only, not the training "
                   "variance\n", bullet);
}

/* ---- Markdown ---------------------------------------------------------- */

static void md_matrix(FILE *f, const tcb_rpt_block *b, int m)
{
    fprintf(f, "%s (row − column):\n\n| |", tcb_cmp_metric_label(m));
    for (int c = 0; c < b->n_rows; c++) fprintf(f, " %s |", b->rows[c].method);
    fprintf(f, "\n|:---|");
    for (int c = 0; c < b->n_rows; c++) fprintf(f, "---:|");
    fprintf(f, "\n");
    for (int r = 0; r < b->n_rows; r++) {
        fprintf(f, "| %s |", b->rows[r].method);
        for (int c = 0; c < b->n_rows; c++) {
            tcb_cmp_metric x;
            const tcb_cmp_metric *p = r == c ? NULL : seen_from(b, r, c, m, &x);
            char text[128];
            cell_text(p, m, text, sizeof text);
            const char *em = p && tcb_cmp_significant(p) ? "**" : "";
            fprintf(f, " %s%s%s |", em, r == c ? "" : text, em);
        }
        fprintf(f, "\n");
    }
    fprintf(f, "\n");
}

static void md_block(FILE *f, const tcb_rpt_block *b)
{
    if (!b->compared || b->n_rows < 2) return;
    fprintf(f, "## %s / %s\n\nrole: %s · seeds: %s\n\n", b->dataset, b->sequence, b->role, b->seeds);
    block_notes(f, b, "- ");
    fprintf(f, "\n");
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (any_compared(b, m)) md_matrix(f, b, m);
}

static void for_blocks(FILE *f, const tcb_rpt *r, void (*w)(FILE *, const tcb_rpt_block *))
{
    for (int d = 0; d < r->n_datasets; d++) {
        const tcb_rpt_dataset *ds = &r->datasets[d];
        for (int k = ds->first; k < ds->first + ds->n; k++) w(f, &r->blocks[k]);
        if (ds->n_test) w(f, &ds->mean);
    }
}

void tcb_rpt_write_cmp_md(FILE *f, const tcb_rpt *r)
{
    fprintf(f, "# tcbench comparisons\n\n"
               "Per sequence and metric, each method (row) minus each other (column), in table units: the "
               "mean difference of the per-pair values (seeds averaged), its 95 %% interval (seeded "
               "hierarchical paired bootstrap: seeds, then pairs; MEAN blocks: the test sequences) and the "
               "Wilcoxon signed-rank p of the per-pair differences, Holm-adjusted over the block's "
               "comparisons of that metric. **bold**: significant (adjusted p < 0.05, interval excluding 0). "
               "docs/protocol.md, \"Statistics of a comparison\".\n\n");
    for_blocks(f, r, md_block);
}

/* ---- LaTeX ------------------------------------------------------------- */

static void tex_matrix(FILE *f, const tcb_rpt_block *b, int m)
{
    fputs("\\begin{table}[t]\n\\centering\n\\caption{", f);
    tcb_rpt_tex_escaped(f, b->dataset);
    fputs(" / ", f);
    tcb_rpt_tex_escaped(f, b->sequence);
    fputs(", ", f);
    tcb_rpt_tex_escaped(f, tcb_rpt_metrics[m].key);
    fputs(": row $-$ column, 95\\,\\% bootstrap interval, Holm-adjusted Wilcoxon $p$; significant in bold.}\n"
          "\\begin{tabular}{l", f);
    for (int c = 0; c < b->n_rows; c++) fputc('c', f);
    fputs("}\n\\toprule\n", f);
    for (int c = 0; c < b->n_rows; c++) fputs(" & ", f), tcb_rpt_tex_escaped(f, b->rows[c].method);
    fputs(" \\\\\n\\midrule\n", f);
    for (int r = 0; r < b->n_rows; r++) {
        tcb_rpt_tex_escaped(f, b->rows[r].method);
        for (int c = 0; c < b->n_rows; c++) {
            tcb_cmp_metric x;
            const tcb_cmp_metric *p = r == c ? NULL : seen_from(b, r, c, m, &x);
            char text[128];
            cell_text(p, m, text, sizeof text);
            if (r == c) fputs(" & ", f);
            else if (p && tcb_cmp_significant(p)) fprintf(f, " & \\textbf{%s}", text);
            else fprintf(f, " & %s", text);
        }
        fputs(" \\\\\n", f);
    }
    fputs("\\bottomrule\n\\end{tabular}\n\\end{table}\n\n", f);
}

static void tex_block(FILE *f, const tcb_rpt_block *b)
{
    if (!b->compared || b->n_rows < 2) return;
    fputs("% ", f);
    fprintf(f, "%s / %s (%s), seeds %s\n", b->dataset, b->sequence, b->role, b->seeds);
    block_notes(f, b, "% ");
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (any_compared(b, m)) tex_matrix(f, b, m);
}

void tcb_rpt_write_cmp_tex(FILE *f, const tcb_rpt *r)
{
    fputs("% tcbench comparisons; needs \\usepackage{booktabs}. docs/protocol.md, \"Statistics of a "
          "comparison\".\n\n", f);
    for_blocks(f, r, tex_block);
}

/* ---- CSV --------------------------------------------------------------- */

static void csv_num(FILE *f, int has, double v)
{
    if (has && !isnan(v)) fprintf(f, ",%.9g", v);
    else fputc(',', f);
}

static void csv_block(FILE *f, const tcb_rpt_block *b)
{
    if (!b->compared) return;
    for (int k = 0; k < b->n_cmp; k++)
        for (int m = 0; m < TCB_N_METRICS; m++) {
            const tcb_rpt_cmp *p = &b->cmp[k];
            const tcb_cmp_metric *x = &p->c.m[m];
            int has = !p->note[0] && x->has;
            tcb_rpt_csv_field(f, b->dataset);
            fputc(',', f);
            tcb_rpt_csv_field(f, b->sequence);
            fprintf(f, ",%s,%s,", b->role, tcb_rpt_metrics[m].key);
            tcb_rpt_csv_field(f, b->rows[p->a].method);
            fputc(',', f);
            tcb_rpt_csv_field(f, b->rows[p->b].method);
            if (has) fprintf(f, ",%d,%d,%d,%s", p->c.seeds_a, p->c.seeds_b, p->c.n,
                             p->c.over_sequences ? "sequences" : "pairs");
            else fputs(",,,,", f);
            csv_num(f, has, x->mean_a), csv_num(f, has, x->mean_b), csv_num(f, has, x->diff);
            csv_num(f, has, x->lo), csv_num(f, has, x->hi), csv_num(f, has, x->p), csv_num(f, has, x->p_holm);
            if (has) fprintf(f, ",%d,%d,", tcb_cmp_significant(x), p->c.resamples);
            else fputs(",,,", f);
            tcb_rpt_csv_field(f, p->note[0] ? p->note : has ? "" : "a side has no value");
            fputc('\n', f);
        }
}

void tcb_rpt_write_cmp_csv(FILE *f, const tcb_rpt *r)
{
    fputs("dataset,sequence,role,metric,method_a,method_b,seeds_a,seeds_b,n,over,mean_a,mean_b,diff,lo,hi,p,"
          "p_holm,significant,resamples,note\n", f);
    for_blocks(f, r, csv_block);
}

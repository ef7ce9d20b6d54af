/* LaTeX tables (booktabs): one table per dataset, a block per sequence,
 * then the MEAN block over the test sequences. */
#include <string.h>

#include "reports/writers.h"

void tcb_rpt_tex_escaped(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '_': case '&': case '%': case '$': case '#': case '{': case '}':
            fprintf(f, "\\%c", *s);
            break;
        case '~': fputs("\\textasciitilde{}", f); break;
        case '^': fputs("\\textasciicircum{}", f); break;
        case '\\': fputs("\\textbackslash{}", f); break;
        default: fputc(*s, f);
        }
    }
}

static void write_block(FILE *f, const tcb_rpt_block *b, const char *title, const unsigned char *shown)
{
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        if (k == 0) tcb_rpt_tex_escaped(f, title);
        fputs(" & ", f);
        tcb_rpt_tex_escaped(f, r->method);
        for (int m = 0; m < TCB_N_METRICS; m++) {
            if (!shown[m]) continue;
            char cell[128];
            tcb_rpt_cell_text(r, m, " $\\pm$ ", cell, sizeof cell);
            if (r->best[m])
                fprintf(f, " & \\textbf{%s}", cell);
            else if (strcmp(r->status, "ok"))
                fprintf(f, " & \\textit{%s}", cell);
            else
                fprintf(f, " & %s%s", cell, r->tie[m] ? "$^{\\approx}$" : "");
        }
        fputs(" \\\\\n", f);
    }
}

static void write_dataset(FILE *f, const tcb_rpt *r, const tcb_rpt_dataset *d)
{
    unsigned char shown[TCB_N_METRICS];
    int n_shown = 0;
    for (int m = 0; m < TCB_N_METRICS; m++) n_shown += shown[m] = (unsigned char)tcb_rpt_dataset_shows(r, d, m);
    fputs("\\begin{table}[t]\n\\centering\n\\caption{", f);
    tcb_rpt_tex_escaped(f, d->name);
    fputs(": m\\_sL2 $\\times 10^{3}$, rank \\%, AUC \\%, CD $\\times 10^{3}$, and the geodesic "
          "error m\\_geo $\\times 10^{3}$ and AUC\\_geo \\%, Corr and Corr-mesh (DynoSurf's computation) $\\times 10^{3}$, CD-L2 $\\times 10^{5}$, NC \\% "
          "and the F-scores at 0.5\\,\\% and 1\\,\\% in \\% (not in the paper's protocol) (mean "
          "$\\pm$ std); in bold the best when significantly better than every other method (Holm-adjusted "
          "Wilcoxon $p < 0.05$ over the block's comparisons of the column and the 95\\,\\% bootstrap interval of "
          "the difference excluding 0), else $^{\\approx}$ on the leaders tied for best; ``-'': no reconstruction "
          "(CD), no clips (Corr), no surface (CD-L2, NC, F) or not scored (geodesic). MEAN: over the test sequences, its intervals rough with few of them.}\n\\begin{tabular}{ll",
          f);
    for (int m = 0; m < n_shown; m++) fputc('c', f);
    fputs("}\n\\toprule\nSequence & Method", f);
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (shown[m]) fprintf(f, " & %s", tcb_rpt_metrics[m].tex_label);
    fputs(" \\\\\n", f);
    for (int k = d->first; k < d->first + d->n; k++) {
        const tcb_rpt_block *b = &r->blocks[k];
        char title[160];
        snprintf(title, sizeof title, "%s (%s)", b->sequence, b->role);
        fputs("\\midrule\n", f);
        write_block(f, b, title, shown);
    }
    fputs("\\midrule\n", f);
    if (d->n_test)
        write_block(f, &d->mean, "MEAN", shown);
    else
        fprintf(f, "\\multicolumn{%d}{l}{\\textit{no test sequence: no MEAN}} \\\\\n",
                2 + n_shown);
    fputs("\\bottomrule\n\\end{tabular}\n\\end{table}\n\n", f);
}

void tcb_rpt_write_tex(FILE *f, const tcb_rpt *r)
{
    char presets[TCB_RPT_PRESETS_MAX];
    int not_paper = tcb_rpt_presets(r, presets);
    fputs("% tcbench results; needs \\usepackage{booktabs}.\n", f);
    if (presets[0])
        fprintf(f, "%% presets: %s%s\n", presets, not_paper ? " (not the paper's training)" : "");
    fputs("\n", f);
    for (int k = 0; k < r->n_datasets; k++) write_dataset(f, r, &r->datasets[k]);
}

/* Markdown tables shaped like the paper's: a block per sequence, a MEAN
 * block per dataset over its test sequences. */
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

static void write_table(FILE *f, const tcb_rpt_block *b)
{
    fprintf(f, "| method |");
    for (int m = 0; m < TCB_N_METRICS; m++) fprintf(f, " %s |", tcb_rpt_metrics[m].label);
    fprintf(f, "\n|:---|");
    for (int m = 0; m < TCB_N_METRICS; m++) fprintf(f, "---:|");
    fprintf(f, "\n");
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        fprintf(f, "| %s |", r->method);
        for (int m = 0; m < TCB_N_METRICS; m++) {
            char cell[128];
            tcb_rpt_cell_text(r, m, " ± ", cell, sizeof cell);
            const char *em = r->best[m] ? "**" : strcmp(r->status, "ok") ? "*" : "";
            fprintf(f, " %s%s%s |", em, cell, em);
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
    fprintf(f, "\n");
}

/* The block's plots, written beside tables.md by the report. */
static void write_plot_links(FILE *f, const tcb_rpt_block *b)
{
    char pck[1024], gap[1024];
    tcb_error err = {0};
    if (tcb_chart_file_name(b, "pck", pck, sizeof pck, &err) ||
        tcb_chart_file_name(b, "gap", gap, sizeof gap, &err))
        return; /* a name too long for a link: the plots are still in the directory */
    fprintf(f, "![PCK curves](%s) ![m_sL2 by frame distance](%s)\n\n", pck, gap);
}

static void write_dataset(FILE *f, const tcb_rpt *r, const tcb_rpt_dataset *d)
{
    fprintf(f, "## %s\n\n", d->name);
    for (int k = d->first; k < d->first + d->n; k++) {
        const tcb_rpt_block *b = &r->blocks[k];
        char pairs[64];
        pairs_text(b, pairs, sizeof pairs);
        fprintf(f, "### %s / %s\n\nrole: %s · pairs: %s · seeds: %s\n\n", d->name, b->sequence,
                b->role, pairs, b->seeds);
        write_table(f, b);
        write_plot_links(f, b);
    }
    if (!d->n_test) {
        fprintf(f, "### %s / MEAN\n\nNo test sequence in this run: no MEAN block.\n\n", d->name);
        return;
    }
    fprintf(f,
            "### %s / MEAN\n\nmean over the %d test sequence%s (%s) of the per-sequence means, "
            "and separately of the per-sequence stds\n\n",
            d->name, d->n_test, d->n_test == 1 ? "" : "s", d->test_sequences);
    write_table(f, &d->mean);
}

void tcb_rpt_write_md(FILE *f, const tcb_rpt *r)
{
    fprintf(f, "# tcbench results\n\n"
               "m_sL2 ×1e3, rank %%, AUC %%, CD ×1e3, as mean ± std (m_sL2 and rank over all "
               "vertices of all pairs, AUC and CD over pairs; seeds pooled). Best per column in "
               "**bold**; \"-\": the method has no reconstruction.\n\n");
    for (int k = 0; k < r->n_datasets; k++) write_dataset(f, r, &r->datasets[k]);
}

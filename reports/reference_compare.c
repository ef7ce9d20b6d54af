/* A run's table rows matched to a reference's rows, and the comparisons a
 * reader of the two tables makes: our/paper per value, and whether the
 * methods come out in the same order. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "reports/reference.h"

static const tcb_rpt_block *find_block(const tcb_rpt *r, const char *dataset, const char *sequence)
{
    if (!strcmp(sequence, "MEAN")) {
        for (int k = 0; k < r->n_datasets; k++)
            if (!strcmp(r->datasets[k].name, dataset) && r->datasets[k].n_test) return &r->datasets[k].mean;
        return NULL;
    }
    for (int k = 0; k < r->n_blocks; k++)
        if (!strcmp(r->blocks[k].dataset, dataset) && !strcmp(r->blocks[k].sequence, sequence)) return &r->blocks[k];
    return NULL;
}

static const tcb_rpt_row *find_row(const tcb_rpt *r, const tcb_ref_row *p, const tcb_rpt_block **block, int *index)
{
    const tcb_rpt_block *b = find_block(r, p->dataset, p->sequence);
    for (int k = 0; b && k < b->n_rows; k++)
        if (!strcmp(b->rows[k].method, p->method)) return *block = b, *index = k, &b->rows[k];
    return NULL;
}

static int same_group(const tcb_ref_row *a, const tcb_ref_row *b)
{
    return !strcmp(a->dataset, b->dataset) && !strcmp(a->sequence, b->sequence);
}

/* Groups are runs of consecutive rows with one (dataset, sequence). */
static int compare_table(const tcb_ref_table *t, const tcb_rpt *r, tcb_ref_cmp_table *out, tcb_error *err)
{
    out->table = t;
    out->groups = calloc((size_t)t->n_rows, sizeof *out->groups);
    if (!out->groups) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    for (int k = 0; k < t->n_rows;) {
        int end = k + 1;
        while (end < t->n_rows && same_group(&t->rows[k], &t->rows[end])) end++;
        tcb_ref_group *g = &out->groups[out->n_groups];
        g->rows = calloc((size_t)(end - k), sizeof *g->rows);
        if (!g->rows) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
        g->dataset = t->rows[k].dataset, g->sequence = t->rows[k].sequence;
        for (int i = k; i < end; i++) {
            tcb_ref_cmp_row *row = &g->rows[g->n_rows++];
            row->paper = &t->rows[i];
            row->ours = find_row(r, &t->rows[i], &row->block, &row->index);
            g->n_ours += row->ours != NULL;
            for (int m = 0; m < TCB_N_METRICS; m++) out->shown[m] |= t->rows[i].has[m];
        }
        if (g->n_ours) out->n_groups++;
        else free(g->rows), memset(g, 0, sizeof *g), out->n_absent++;
        k = end;
    }
    return TCB_OK;
}

static int names_a_cell(const tcb_ref_table *t, const tcb_rpt *r)
{
    const tcb_rpt_block *b;
    int index;
    for (int k = 0; k < t->n_rows; k++)
        if (find_row(r, &t->rows[k], &b, &index)) return 1;
    return 0;
}

int tcb_ref_compare(const tcb_reference *ref, const tcb_rpt *r, const char (*ids)[16], int n_ids, tcb_ref_cmp *out,
                    tcb_error *err)
{
    memset(out, 0, sizeof *out);
    out->ref = ref;
    out->run = r;
    out->tables = calloc((size_t)ref->n_tables, sizeof *out->tables);
    if (!out->tables) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    int rc = TCB_OK;
    for (int k = 0; k < n_ids && !rc; k++) {
        const tcb_ref_table *t = tcb_reference_table(ref, ids[k]);
        if (!t) rc = tcb_fail(err, TCB_ERR_INPUT, "reference %s has no table '%s'", ref->name, ids[k]);
        else rc = compare_table(t, r, &out->tables[out->n_tables++], err);
    }
    for (int k = 0; !n_ids && k < ref->n_tables && !rc; k++)
        if (names_a_cell(&ref->tables[k], r)) rc = compare_table(&ref->tables[k], r, &out->tables[out->n_tables++], err);
    if (!rc && !out->n_tables)
        rc = tcb_fail(err, TCB_ERR_INPUT, "no table of reference %s names a cell of this run", ref->name);
    if (rc) tcb_ref_cmp_free(out);
    return rc;
}

void tcb_ref_cmp_free(tcb_ref_cmp *c)
{
    for (int k = 0; k < c->n_tables; k++) {
        for (int g = 0; g < c->tables[k].n_groups; g++) free(c->tables[k].groups[g].rows);
        free(c->tables[k].groups);
    }
    free(c->tables);
    memset(c, 0, sizeof *c);
}

static int usable(const tcb_ref_cmp_row *row, int m)
{
    return row->ours && !strcmp(row->ours->status, "ok") && row->ours->has[m] && row->paper->has[m];
}

double tcb_ref_ratio(const tcb_ref_cmp_row *row, int m)
{
    return usable(row, m) && row->paper->mean[m] != 0 ? row->ours->mean[m] / row->paper->mean[m] : NAN;
}

int tcb_ref_far(const tcb_ref_cmp_row *row, int m)
{
    double q = tcb_ref_ratio(row, m);
    return q > TCB_REF_FAR || q < 1 / TCB_REF_FAR; /* false for NaN */
}

/* > 0 when row a is better than row b by metric m, in the paper (ours 0) or here (ours 1). */
static int better(const tcb_ref_cmp_row *a, const tcb_ref_cmp_row *b, int m, int ours)
{
    double va = ours ? a->ours->mean[m] : a->paper->mean[m], vb = ours ? b->ours->mean[m] : b->paper->mean[m];
    int sign = (va < vb) - (va > vb);
    return tcb_rpt_metrics[m].lower_is_better ? sign : -sign;
}

tcb_ref_order tcb_ref_order_of(const tcb_ref_group *g, int i, int j, int m, int *better_row)
{
    const tcb_ref_cmp_row *ri = &g->rows[i], *rj = &g->rows[j];
    if (!usable(ri, m) || !usable(rj, m)) return TCB_REF_UNORDERED;
    int p = better(ri, rj, m, 0), o = better(ri, rj, m, 1);
    if (!p || !o) return TCB_REF_UNORDERED; /* a tie on either side orders nothing */
    *better_row = p > 0 ? i : j;
    if (p == o) return TCB_REF_AGREES;
    const tcb_ref_cmp_row *ours_better = o > 0 ? ri : rj, *ours_worse = o > 0 ? rj : ri;
    return ri->block == rj->block && tcb_rpt_beats(ri->block, ours_better->index, ours_worse->index, m)
               ? TCB_REF_FLIPS_SIGNIFICANT
               : TCB_REF_FLIPS_NOISE;
}

/* The grid's cells in one fixed order — datasets, their sequences, the
 * methods that run on the dataset, their seeds — numbered from 0. An id
 * depends only on the config, never on what has run, so `--cell 7` and
 * `--shard 2/8` name the same work on every machine and after every
 * restart. Also which cells a run selects (--only) and how the engine
 * names a cell in progress lines, logs and model records. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_internal.h"

int tcb_run_selected(const tcb_run_opts *opts, const tcb_method_spec *m)
{
    return !opts->only_method || strcmp(opts->only_method, m->label) == 0;
}

void tcb_cell_label(char *out, size_t size, const char *dataset, const char *sequence,
                    const char *method, int seed)
{
    snprintf(out, size, "%s/%s/%s/seed %d", dataset, sequence, method, seed);
}

int tcb_grid_cells_per_sequence(const tcb_config *cfg, const tcb_dataset_spec *d)
{
    int n = 0;
    for (int k = 0; k < cfg->n_methods; k++)
        if (tcb_method_runs_on(&cfg->methods[k], d->name)) n += cfg->methods[k].n_seeds;
    return n;
}

int tcb_grid_count(const tcb_config *cfg)
{
    int n = 0;
    for (int k = 0; k < cfg->n_datasets; k++)
        n += cfg->datasets[k].n_sequences * tcb_grid_cells_per_sequence(cfg, &cfg->datasets[k]);
    return n;
}

int tcb_grid_for_each(const tcb_config *cfg, tcb_grid_visit visit, void *ctx)
{
    int id = 0;
    for (int k = 0; k < cfg->n_datasets; k++) {
        const tcb_dataset_spec *d = &cfg->datasets[k];
        for (int s = 0; s < d->n_sequences; s++)
            for (int m = 0; m < cfg->n_methods; m++) {
                if (!tcb_method_runs_on(&cfg->methods[m], d->name)) continue;
                for (int e = 0; e < cfg->methods[m].n_seeds; e++) {
                    tcb_grid_cell c = {id++, d, &d->sequences[s], &cfg->methods[m], cfg->methods[m].seeds[e]};
                    int rc = visit(ctx, &c);
                    if (rc) return rc;
                }
            }
    }
    return TCB_OK;
}

static int parse_id(const char *s, const char *end, int n_cells, const char *spec, int *out, tcb_error *err)
{
    char *stop;
    errno = 0;
    long v = strtol(s, &stop, 10);
    if (s == end || stop != end || errno || v < 0)
        return tcb_fail(err, TCB_ERR_INPUT, "--cell %s: expected ids and ranges such as 3,5-7", spec);
    if (v >= n_cells)
        return tcb_fail(err, TCB_ERR_INPUT, "--cell %s: cell %ld does not exist (the config has %d cells, 0-%d)",
                        spec, v, n_cells, n_cells - 1);
    *out = (int)v;
    return TCB_OK;
}

int tcb_cell_set_parse(const char *spec, int n_cells, unsigned char *mask, tcb_error *err)
{
    memset(mask, 0, (size_t)n_cells);
    for (const char *p = spec;;) {
        const char *comma = strchr(p, ','), *end = comma ? comma : p + strlen(p);
        const char *dash = memchr(p, '-', (size_t)(end - p));
        int lo = 0, hi = 0, rc = parse_id(p, dash ? dash : end, n_cells, spec, &lo, err);
        if (!rc) rc = dash ? parse_id(dash + 1, end, n_cells, spec, &hi, err) : (hi = lo, TCB_OK);
        if (rc) return rc;
        if (hi < lo) return tcb_fail(err, TCB_ERR_INPUT, "--cell %s: range %d-%d runs backwards", spec, lo, hi);
        for (int k = lo; k <= hi; k++) mask[k] = 1;
        if (!comma) return TCB_OK;
        p = comma + 1;
    }
}

static int env_int(const char *name, long *out)
{
    const char *v = getenv(name);
    char *end;
    if (!v || !*v) return 0;
    errno = 0;
    *out = strtol(v, &end, 10);
    return !*end && !errno;
}

/* Slurm's array task: its index among the array's tasks and their count. */
static int slurm_shard(int *index, int *count, tcb_error *err)
{
    long id, n, lo, hi;
    if (!env_int("SLURM_ARRAY_TASK_ID", &id))
        return tcb_fail(err, TCB_ERR_INPUT, "--shard auto: SLURM_ARRAY_TASK_ID is not set (not a Slurm array task)");
    if (env_int("SLURM_ARRAY_TASK_MIN", &lo) && env_int("SLURM_ARRAY_TASK_MAX", &hi)) n = hi - lo + 1, id -= lo;
    else if (!env_int("SLURM_ARRAY_TASK_COUNT", &n))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "--shard auto: neither SLURM_ARRAY_TASK_MIN/MAX nor SLURM_ARRAY_TASK_COUNT is set");
    if (n < 1 || id < 0 || id >= n)
        return tcb_fail(err, TCB_ERR_INPUT, "--shard auto: task %ld of %ld is outside the array", id, n);
    *index = (int)id, *count = (int)n;
    return TCB_OK;
}

int tcb_shard_parse(const char *spec, int n_cells, unsigned char *mask, tcb_error *err)
{
    int index, count, used = 0;
    if (!strcmp(spec, "auto")) {
        int rc = slurm_shard(&index, &count, err);
        if (rc) return rc;
    } else if (sscanf(spec, "%d/%d%n", &index, &count, &used) != 2 || spec[used] || count < 1 || index < 0 ||
               index >= count) {
        return tcb_fail(err, TCB_ERR_INPUT, "--shard %s: expected I/N with 0 <= I < N, or auto", spec);
    }
    for (int k = 0; k < n_cells; k++) mask[k] = mask[k] && k % count == index;
    return TCB_OK;
}

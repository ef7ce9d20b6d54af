/* One cell of a finished run picked by name for a closer look (`tcbench
 * inspect`, `tcbench frames`): the run's config, the cell's dataset,
 * sequence, method and seed, and everything needed to reopen its fitted
 * model. Shared so both commands accept and refuse the same names with the
 * same messages. */
#include <stdio.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/registry.h"
#include "views/cell_target.h"

int tcb_run_config_open(const char *run_dir, tcb_config *cfg, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = tcb_path_join(path, sizeof path, err, "%s/config.json", run_dir);
    if (rc) return rc;
    if (!tcb_is_file(path))
        return tcb_fail(err, TCB_ERR_IO, "%s: no such file: %s is not a run directory", path, run_dir);
    if ((rc = tcb_config_load(path, cfg, err))) return rc;
    if ((rc = tcb_harness_load_plugins(cfg, err))) tcb_config_free(cfg);
    return rc;
}

static int resolve_sequence(const tcb_config *cfg, const char *want, tcb_cell_target *t, tcb_error *err)
{
    int n = 0;
    char names[512] = ""; /* for the message; names that do not fit are left out */
    for (int a = 0; a < cfg->n_datasets; a++)
        for (int b = 0; b < cfg->datasets[a].n_sequences; b++) {
            const tcb_dataset_spec *d = &cfg->datasets[a];
            char name[TCB_PATH_MAX];
            snprintf(name, sizeof name, "%s/%s", d->name, d->sequences[b].name);
            size_t used = strlen(names);
            if (used + strlen(name) + 3 < sizeof names) {
                if (used) strcat(names, ", ");
                strcat(names, name);
            }
            if (!want || strcmp(want, name) == 0) t->d = d, t->s = &d->sequences[b], n++;
        }
    if (n == 1) return TCB_OK;
    if (want)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: no sequence '%s' (the run's: %s)", cfg->path,
                        want, names);
    return tcb_fail(err, TCB_ERR_INPUT, "%s has %d sequences: choose one with --sequence (%s)",
                    cfg->path, n, names);
}

int tcb_cell_target_resolve(const tcb_config *cfg, const char *method, int seed, const char *sequence,
                            tcb_cell_target *t, tcb_error *err)
{
    *t = (tcb_cell_target){0};
    int rc = resolve_sequence(cfg, sequence, t, err);
    if (rc) return rc;
    for (int k = 0; k < cfg->n_methods; k++)
        if (strcmp(cfg->methods[k].label, method) == 0) t->m = &cfg->methods[k];
    if (!t->m) return tcb_fail(err, TCB_ERR_INPUT, "%s: no method labelled '%s'", cfg->path, method);
    if (!(t->ops = tcb_registry_find(t->m->method)))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: method '%s' is not registered (a plug-in?)",
                        cfg->path, t->m->method);
    /* Recomputing a cell with another build of its plug-in would compare
     * other code's numbers with the cell's. */
    const char *digest = tcb_registry_digest(t->ops);
    if (t->m->plugin_digest[0] && digest && strcmp(digest, t->m->plugin_digest) != 0)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s: %s's cells were computed by the build %s of its plug-in, but %s is %s (rebuilt "
                        "since): recompute them with 'tcbench run CONFIG --force --only %s' first",
                        cfg->path, t->m->label, t->m->plugin_digest, tcb_registry_file(t->ops), digest,
                        t->m->label);
    t->seed = seed >= 0 ? seed : t->m->seeds[0];
    for (int k = 0; k < t->m->n_seeds; k++)
        if (t->m->seeds[k] == t->seed) return TCB_OK;
    return tcb_fail(err, TCB_ERR_INPUT, "%s: seed %d is not one of %s's seeds in this run",
                    cfg->path, t->seed, t->m->label);
}

int tcb_cell_session_open(const tcb_config *cfg, const char *run_dir, const tcb_cell_target *t,
                          int threads, tcb_reporter reporter, tcb_cell_session *s, tcb_error *err)
{
    memset(s, 0, sizeof *s);
    int rc = tcb_harness_load_sequence(cfg, t->d, t->s, &reporter, &s->seq, err);
    if (!rc) rc = tcb_harness_obtain_split(cfg, t->d, t->s, &s->seq, s->split_path,
                                           sizeof s->split_path, &s->split, err);
    if (!rc) rc = tcb_harness_work_paths(run_dir, t->d->name, t->s->name, t->m->label, t->seed,
                                         s->work, s->ckpt, err);
    if (!rc) rc = tcb_mkdirs(s->work, err);
    if (rc) {
        tcb_cell_session_close(s);
        return rc;
    }
    s->job = (tcb_cell_job){
        .seq = &s->seq,
        .split = &s->split,
        .split_path = s->split_path,
        .dataset = t->d,
        .method = t->m,
        .ops = t->ops,
        .seed = t->seed,
        .threads = threads > 0 ? threads : cfg->threads,
        .reuse_checkpoint = 1,
        .require_checkpoint = 1,
        .work_dir = s->work,
        .checkpoint = s->ckpt,
        .git_revision = "",
        .reporter = reporter,
    };
    return TCB_OK;
}

void tcb_cell_session_close(tcb_cell_session *s)
{
    tcb_split_free(&s->split);
    tcb_sequence_free(&s->seq);
}

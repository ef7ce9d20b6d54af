#include "neural/train_loop.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>

#include "tcb/fsutil.h"

/* Continues from path when there is a checkpoint there; *earlier_s gets
 * the seconds it cost (0 when training starts afresh). */
static void resume(const tcb_train_loop *loop, const tcb_fit_ctx *ctx, const char *path, double *earlier_s)
{
    *earlier_s = 0;
    if (!path[0] || !tcb_is_file(path)) return;
    tcb_error e = {0};
    if (loop->load(loop->trainer, path, earlier_s, &e) == TCB_OK)
        tcb_report_log(&ctx->reporter, TCB_LOG_INFO, "%s: resuming training at iteration %lld from %s (%.0f s in)",
                       loop->name, loop->done(loop->trainer), path, *earlier_s);
    else
        tcb_report_log(&ctx->reporter, TCB_LOG_WARN, "%s: not resumed (%s); training from the start", loop->name,
                       e.msg);
}

/* Iterations between two loss lines: 1 000, or a tenth of a shorter
 * training, so that every training shows its curve. */
static long long log_interval(long long total)
{
    long long tenth = total / 10;
    return tenth < 1 ? 1 : tenth < 1000 ? tenth : 1000;
}

static int run(const tcb_train_loop *loop, const tcb_fit_ctx *ctx, tcb_error *err)
{
    double start = tcb_now_seconds(), earlier = 0;
    char ckpt[TCB_PATH_MAX] = "";
    int rc = TCB_OK;
    /* Also without periodic checkpoints: a stop request saves one. */
    if (ctx->work_dir) rc = tcb_path_join(ckpt, sizeof ckpt, err, "%s/%s", ctx->work_dir, loop->ckpt_name);
    if (!rc) resume(loop, ctx, ckpt, &earlier);
    long long total = loop->iterations, every = log_interval(total), since = 0;
    double sum = 0;
    while (!rc && loop->done(loop->trainer) < total) {
        double loss;
        rc = loop->step(loop->trainer, &loss, err);
        long long done = loop->done(loop->trainer);
        sum += loss, since++;
        if (!rc && (done % 10 == 0 || done == total))
            tcb_report_progress(&ctx->reporter, (double)done, (double)total, loop->name);
        if (!rc && (done % every == 0 || done == total)) {
            tcb_report_log(&ctx->reporter, TCB_LOG_DEBUG, "%s: iteration %lld mean loss %.6g over the last %lld",
                           loop->name, done, sum / (double)since, since);
            sum = 0, since = 0;
        }
        int periodic = loop->checkpoint_every > 0 && done % loop->checkpoint_every == 0;
        int stop = !rc && done < total && tcb_fit_interrupted(ctx);
        const char *said = ckpt[0] ? "; training state saved in " : " (no work directory: nothing saved)";
        const char *where = ckpt;
        if (!rc && ckpt[0] && (periodic || stop) && done < total) {
            tcb_error se = {0};
            /* A state that cannot be written (a full disk) costs only the
             * resumption, not the training: the training goes on, and a
             * failed cell would stay failed once the disk has room again. */
            if (loop->save(loop->trainer, earlier + tcb_now_seconds() - start, ckpt, &se)) {
                tcb_report_log(&ctx->reporter, TCB_LOG_WARN, "%s: training state not saved: %s", loop->name, se.msg);
                said = " (the training state could not be saved)", where = "";
            }
        }
        if (!rc && stop)
            return tcb_fail(err, TCB_ERR_INTERRUPTED, "stopped at iteration %lld of %lld%s%s", done, total, said,
                            where);
    }
    if (ctx->resumed_fit_s) *ctx->resumed_fit_s = earlier;
    if (!rc && ckpt[0]) remove(ckpt);
    return rc;
}

int tcb_train_loop_run(const tcb_train_loop *loop, const tcb_fit_ctx *ctx, tcb_error *err)
{
    int prev_threads = omp_get_max_threads();
    if (ctx->n_threads > 0) omp_set_num_threads(ctx->n_threads);
    int rc = run(loop, ctx, err);
    omp_set_num_threads(prev_threads);
    if (rc) tcb_error_prefix(err, "%s: ", loop->name);
    return rc;
}

int tcb_train_guard(const char *name, long long it, double loss, const float *grads, size_t n,
                    double divergence, double *loss0, tcb_error *err)
{
    int rc = TCB_OK;
    for (size_t k = 0; k < n && !rc; k++)
        if (!isfinite(grads[k])) rc = tcb_fail(err, TCB_ERR_NUMERIC, "%s: non-finite gradient", name);
    if (!rc && it == 0) *loss0 = loss;
    if (!rc && divergence > 0 && loss > divergence * *loss0)
        rc = tcb_fail(err, TCB_ERR_NUMERIC, "%s: diverged, loss %g > %g x the first iteration's %g", name,
                      loss, divergence, *loss0);
    if (rc) tcb_error_prefix(err, "iteration %lld: ", it);
    return rc;
}

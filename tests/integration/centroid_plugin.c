/* A small out-of-tree plug-in for the tests of what tcbench does when a
 * new method goes wrong (test_plugin_faults.sh, test_errors_doc.sh): the
 * frames' centroids aligned, then nearest, as a new user writes one. Its
 * faults are planted without changing its code, so that a rerun without
 * them is the fix: CENTROID_FAULT=huge|nan|ids:SEQUENCE breaks its
 * transfer on that sequence (one point at 1e30, one NaN, vertex ids
 * written as x). Built with -D, it is other code: SHIFT (a rebuilt
 * plug-in), ABI (a table of another ABI), NULL_TRANSFER (an incomplete
 * table), NAME (another method name), NO_ENTRY (no entry symbol). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <tcb/method.h>
#ifndef SHIFT
#define SHIFT 0.0f
#endif
#ifndef ABI
#define ABI TCB_METHOD_ABI_VERSION
#endif
#ifndef NAME
#define NAME "centroid"
#endif
#ifndef VERSION
#define VERSION "1.0"
#endif
#ifdef NO_ENTRY
#define tcb_plugin_methods not_the_entry
#endif
static int create(const char *params, void **self, tcb_error *err)
{
    (void)params;
    *self = malloc(1);
    return *self ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "centroid: out of memory");
}
static int fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    (void)self, (void)seq, (void)ctx, (void)err;
    return TCB_OK;
}
static void centroid(const float *v, int n, double c[3])
{
    c[0] = c[1] = c[2] = 0;
    for (int k = 0; k < 3 * n; k++) c[k % 3] += v[k] / n;
}
static int transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                    tcb_rng *rng, tcb_error *err)
{
    (void)self, (void)rng, (void)err;
    double ci[3], cj[3];
    centroid(seq->verts + (size_t)i * seq->n_verts * 3, seq->n_verts, ci);
    centroid(seq->verts + (size_t)j * seq->n_verts * 3, seq->n_verts, cj);
    for (int k = 0; k < 3 * n; k++) out[k] = src[k] + (float)(cj[k % 3] - ci[k % 3]) + SHIFT;
    const char *fault = getenv("CENTROID_FAULT"), *on = fault ? strchr(fault, ':') : NULL;
    if (!on || strcmp(on + 1, seq->name) != 0) return TCB_OK;
    if (!strncmp(fault, "huge", 4)) out[3 * (n / 2)] = 1e30f;
    if (!strncmp(fault, "nan", 3)) out[3 * (n / 2) + 1] = NAN;
    if (!strncmp(fault, "ids", 3))
        for (int v = 0; v < n; v++) out[3 * v] = (float)v, out[3 * v + 1] = out[3 * v + 2] = 0;
    return TCB_OK;
}
static void destroy(void *self) { free(self); }
static const tcb_method_ops centroid_ops = {
    .abi_version = ABI, .name = NAME, .description = "nearest after aligning the frames' centroids",
    .create = create, .fit = fit,
#ifndef NULL_TRANSFER
    .transfer = transfer,
#endif
    .destroy = destroy, .version = VERSION};
const tcb_method_ops *const *tcb_plugin_methods(int *count);
const tcb_method_ops *const *tcb_plugin_methods(int *count)
{
    static const tcb_method_ops *const t[] = {&centroid_ops};
    *count = 1;
    return t;
}

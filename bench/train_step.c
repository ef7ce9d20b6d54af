/* One whole training iteration of each trained method, beside PyTorch.
 *
 * The atlas family (tcb_atlas_train_step:
 * the batch drawn from the point pools, forward, the method's loss,
 * backward, Adam), for atlasnet (Chamfer, no tangents), dsr (Chamfer +
 * 0.001·L_sciso) and mca (Chamfer + 0.1·L_mc; both with the UV-Jacobians), at the paper's scale (C 1024, P 10,
 * M 2500, N 2500) and the cpu preset's (C 256, P 10, M 1000, N 2500), beside
 * the same step in PyTorch on the CPU in the same run
 * (train_step_torch.py: tests/pytorch/atlas_torch.py's reference step,
 * autograd's double backward for mca, torch.optim.Adam), printed as the
 * ratio torch ms / C ms.
 *
 * C: the method's own training steps (train_steps, created with {"preset":
 * P}) on the calibration sequence (synthetic, 6 frames, pools of 10,000
 * points), one warm-up step, then the mean of `iters` steps: the
 * measurement `tcbench calibrate` makes (costs/step_timing.c). The PyTorch peer runs after the C
 * rows of the same (preset, method), with the same sizes, thread count and
 * warm-up; the C process waits meanwhile.
 *
 * GFLOP/s counts the network's minimal FLOPs (atlas_bench.h: the split-
 * first-layer GEMMs, values + tangents rows for mca, the backward's weight
 * and input gradients, the encoder); losses and Adam are timed but not
 * counted. The machine's own rate, measured in the same run at the same
 * thread count: OpenBLAS's sgemm on a 2048³ product (%sq: the step's
 * GFLOP/s over it) and on the step's dominant product (%shp, and the shape
 * m×n×k: atlas the decoder's second layer, (1+nt)·B·m rows × H1 → H2, or
 * the encoder's last convolution, B·N rows × 128 → C, whichever has more
 * multiply-adds; cc that convolution; neupig the MLP's hidden layer, T·nv
 * rows × H → H), each a warm-up call and then calls for 0.3 s; and, after
 * the rows, its memory's rate on a triad (memory_triad), which bounds the
 * thread scaling of the passes that are not products. RSS: each process's peak
 * resident set (getrusage ru_maxrss); the C process's is its peak so far,
 * as the rows run from the smaller preset up.
 *
 * cc (tcb_cc_train_step after the warm-up: the batch drawn from the pools
 * and augmented, six network calls, the cycle losses, backward, Adam) at
 * the paper's scale (C 1024, Z 512, H 64, L 6, 16 triplets of 2500 points)
 * and the cpu preset's (C 128, Z 64, H 32, L 6, 8 triplets of 500),
 * beside train_step_cc_torch.py (the CC code's train_iteration with its
 * latent reuse, torch.optim.Adam; data loading not timed). GFLOP/it counts
 * cc_bench.h's products; the losses' nearest-neighbour searches are timed
 * but not counted.
 *
 * neupig (one epoch of tcb_neupig_train_step: every frame's deformation,
 * the robust Chamfer against every frame's cloud, the edge term, backward,
 * Adam) at the paper preset (8 levels of 30 features, width 512, 5 000
 * points a frame, a template of up to 20 000 triangles) and the cpu
 * preset's sizes, on the calibration sequence's 6 frames; its template is
 * the method's own (Poisson surface of the keyframe, the `surface` of the
 * trained model), written to a temporary OBJ for the peer
 * train_step_neupig_torch.py (tests/pytorch/neupig_torch.py's reference
 * loss, float32, torch.optim.Adam with the per-level rates). GFLOP/it
 * counts the MLP: T*nv*(Din*H + H^2 + 7H) multiply-adds forward, 2x that
 * backward; the grids, the Chamfer's nearest neighbours, the edge term and
 * Adam are timed but not counted.
 *
 * pdg (one epoch of tcb_pdg_train_step after the warm-up: the input term
 * over the 5 transitions, both chains from the keyframe with their catch-up
 * weights and edge term, the template's robust Chamfer through its Large-
 * Steps solve, backward, Adam) at the paper preset (10 levels, 5 000
 * points a frame, a template of up to 20 000 triangles) and the cpu
 * preset's (10 levels, 2 500 points, up to 10 000 triangles), on the
 * calibration sequence's 6 frames. Its train_steps, as `tcbench
 * calibrate`'s, times the main phase: every term from the first epoch
 * (the 101 warm-up epochs, the input term alone, are 2 % of a paper fit
 * and 5 % of a cpu one). The peer train_step_pdg_torch.py
 * (tests/pytorch/pdg_torch.py's reference loss, float32, torch.optim.Adam
 * with the per-level rates) trains on the C training's own data, written
 * to a temporary directory: every frame's cloud in the fields' cube, the
 * keyframe, the template as it started. --losses prints the loss parts of
 * both sides' first two epochs on stderr (C's from two more, untimed,
 * epochs before the timed ones): the same epochs on the same data give the
 * same numbers. No GFLOP count ("-"): the epoch is nearest-neighbour
 * searches, scattered trilinear samples and small solves, no product a
 * FLOP peak would measure.
 *
 * dynosurf (one step of stage 2, its train_steps' main phase: the
 * template carried into every frame by the 30 control points, surface
 * samples, the robust Chamfer and normal terms, the keyframe's identity,
 * the SDF sign on grid picks, the smoothness, backward, Adam) at the cpu
 * preset's sizes and the paper's, on the calibration sequence's 6 frames,
 * its template the zero set of the hull's signed distance (the
 * pretraining's target; dyno_trainer_main_phase). The peer
 * train_step_dynosurf_torch.py (tests/pytorch/dynosurf_torch.py's pieces,
 * float32, torch.optim.Adam) trains on the C training's data. GFLOP/it
 * counts the blend network, (template vertices + grid picks) x 30 rows
 * through 6 -> 128 x 5 -> 1, forward and 2x backward: the dominant product
 * is its hidden layer.
 *
 * Targets (issue 41): every paper-scale step ≥ 5× PyTorch at 1 thread,
 * the GEMM-dominated steps at ≥ 60 % of the sgemm rate on their own
 * dominant product (%shp). The column `ceiling` bounds the first: the
 * peer's time over the counted FLOPs at the 2048³ rate, the torch/C of a
 * C step that did nothing but its GEMMs at the machine's best rate (a step
 * passes it only by running its GEMMs faster than OpenBLAS runs 2048³, or
 * by doing fewer FLOPs than counted). Timings only; nothing is asserted.
 *
 * usage: bench_train_step [--iters N] [--threads T] [--preset paper|cpu|all]
 *                         [--method NAME] [--no-torch]
 *                         [--torch SCRIPT] [--cc-torch SCRIPT]
 *                         [--neupig-torch SCRIPT] [--pdg-torch SCRIPT]
 *                         [--dynosurf-torch SCRIPT] [--losses]
 * Defaults: 5 iterations, the OpenMP thread count, all presets and methods
 * (atlasnet, dsr, mca, cc, neupig, pdg, dynosurf), the peers
 * train_step_torch.py, train_step_cc_torch.py, train_step_neupig_torch.py,
 * train_step_pdg_torch.py and train_step_dynosurf_torch.py next to this
 * file run by /usr/bin/python3. */
#include <cblas.h>
#include <dirent.h>
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include "atlas_bench.h"
#include "cc_bench.h"
#include "costs/step_timing.h"
#include "methods/dynosurf/train.h"
#include "methods/pcgrid/method.h"
#include "methods/pdg/train.h"
#include "tcb/mesh_io.h"
#include "tcb/npy.h"
#include "tcb/registry.h"

/* LOSS_EPOCHS: the epochs whose losses --losses prints: the first at zero
 * fields, the second after a step (solves, gradients and Adam). */
enum { P = 10, N = TCB_DEFAULT_INPUT_POINTS, PEER_SKIPPED = 77, LOSS_EPOCHS = 2 };

typedef struct {
    const char *name;
    int C, M;
} preset;

static const preset presets[] = {{"cpu", 256, 1000}, {"paper", 1024, 2500}};

/* cc_method.c's presets, in the order of presets[] */
typedef struct {
    const char *name;
    tcb_cc_dims d;
    int B, N;
} cc_preset;

static const cc_preset cc_presets[] = {{"cpu", {128, 64, 32, 6, 0}, 8, 500}, {"paper", {1024, 512, 64, 6, 0}, 16, 2500}};

/* neupig_method.c's presets, in the order of presets[]: the MLP's input
 * (features + 2 normal features + 8 time features) and width, the grid
 * levels and features, the points per frame, for the peer and the FLOPs. */
typedef struct {
    int din, hidden, levels, features, points;
} neupig_preset;

static const neupig_preset neupig_presets[] = {{16 + 2 + 8, 128, 6, 16, 2500}, {30 + 2 + 8, 512, 8, 30, 5000}};

static const struct {
    const char *name;
    int nt; /* tangents per value */
} methods[] = {{"atlasnet", 0}, {"dsr", 2}, {"mca", 2}};

typedef struct {
    int iters, threads, torch, losses;
    double sgemm_square; /* GFLOP/s of the 2048³ sgemm, measured at the start */
    char dominant[64];   /* print_row's scratch */
    const char *preset; /* NULL: all */
    const char *method; /* NULL: all */
    char script[4096], cc_script[4096], neupig_script[4096], pdg_script[4096], dynosurf_script[4096];
} options;

#define die(...) bench_die("bench_train_step", __VA_ARGS__)

/* A product C[m][n] = A[m][k]·B[k][n]; m 0: none (pdg's epoch has none). */
typedef struct {
    int m, n, k;
} gemm_shape;

static double macs_of(gemm_shape g) { return (double)g.m * g.n * g.k; }

/* GFLOP/s of OpenBLAS's row-major sgemm of shape g at the current thread
 * count: one warm-up call, then calls until 0.3 s have passed. */
static double sgemm_gflops(gemm_shape g)
{
    float *a = malloc(sizeof(float) * (size_t)g.m * g.k), *b = malloc(sizeof(float) * (size_t)g.k * g.n),
          *c = malloc(sizeof(float) * (size_t)g.m * g.n);
    if (!a || !b || !c) die("sgemm %dx%dx%d: out of memory", g.m, g.n, g.k);
    for (size_t i = 0; i < (size_t)g.m * g.k; i++) a[i] = (float)(i % 7) * 0.1f;
    for (size_t i = 0; i < (size_t)g.k * g.n; i++) b[i] = (float)(i % 5) * 0.1f;
    int reps = 0;
    double t0 = 0, t = 0;
    for (int warm = 1; warm >= 0 || t < 300; warm--) {
        if (warm == 0) t0 = bench_now_ms();
        cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, g.m, g.n, g.k, 1.0f, a, g.k, b, g.n, 0.0f, c, g.n);
        if (warm <= 0) reps++, t = bench_now_ms() - t0;
    }
    free(a), free(b), free(c);
    return 2.0 * macs_of(g) * reps / (t * 1e6);
}

/* GB/s of the triad c = 1.5·a + b over arrays of 40 M floats (PointNet's
 * last activation at the paper's scale, 160 MB each: far past the caches)
 * at the current thread count, the best of 5: the rate of the step's
 * memory-bound passes (batch norms, ReLUs, bias fills), whose 1 → 2 thread
 * ratio bounds theirs as sgemm's bounds the products'. */
static double memory_triad(void)
{
    size_t n = (size_t)40 << 20;
    float *a = malloc(n * sizeof(float)), *b = malloc(n * sizeof(float)), *c = malloc(n * sizeof(float));
    if (!a || !b || !c) die("triad: out of memory");
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) a[i] = (float)(i % 7), b[i] = 1.0f, c[i] = 0.0f;
    double best = 1e30;
    for (int r = 0; r < 5; r++) {
        double t0 = bench_now_ms();
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) c[i] = 1.5f * a[i] + b[i];
        double t = bench_now_ms() - t0;
        if (t < best) best = t;
    }
    volatile float sink = c[n / 2];
    (void)sink;
    free(a), free(b), free(c);
    return 3.0 * n * sizeof(float) / (best * 1e6);
}

/* The atlas step's dominant product (the header's comment). */
static gemm_shape atlas_dominant(int C, int M, int B, int nt)
{
    gemm_shape dec = {(1 + nt) * B * (M / P), (C + 2) / 2, C + 2}, enc = {B * N, C, 128};
    return macs_of(dec) >= macs_of(enc) ? dec : enc;
}

/* Method `name` created with {"preset": preset}; *ops its table. */
static void *create_at(const char *name, const char *preset, const tcb_method_ops **ops)
{
    char params[128];
    snprintf(params, sizeof params, "{\"preset\": \"%s\"}", preset);
    tcb_error err = {0};
    void *self;
    *ops = tcb_registry_find(name);
    if (!*ops || (*ops)->create(params, &self, &err)) die("%s: %s", name, *ops ? err.msg : "not registered");
    if ((*ops)->abi_version < 5 || !(*ops)->train_steps) die("%s: no train_steps in its table", name);
    return self;
}

/* Mean ms per training step of a created method, after one warm-up step:
 * the measurement `tcbench calibrate` makes (tcb_time_train_steps through
 * the method's train_steps). */
static double time_steps(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, const options *o)
{
    tcb_fit_ctx ctx = {.seed = 1, .n_threads = o->threads};
    tcb_step_timing t;
    tcb_error err = {0};
    if (tcb_time_train_steps(ops, self, seq, &ctx, o->iters, INFINITY, &t, &err)) die("%s", err.msg);
    return t.step_s * 1e3;
}

/* time_steps of method `name` created at `preset`. */
static double time_c(const char *name, const char *preset, const tcb_sequence *seq, const options *o)
{
    const tcb_method_ops *ops;
    void *self = create_at(name, preset, &ops);
    double ms = time_steps(ops, self, seq, o);
    ops->destroy(self);
    return ms;
}

/* The surface of frame 0 of a method trained by train_steps, as an OBJ at
 * path; its vertex count. */
static int write_surface(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, const char *path)
{
    tcb_uv_mesh m = {0, 0, 0, NULL, NULL, NULL, NULL};
    tcb_rng rng;
    tcb_error err = {0};
    tcb_rng_seed_stream(&rng, 1, "bench/surface");
    if (ops->abi_version < 3 || !ops->surface) die("%s: no surface in its table", ops->name);
    if (ops->surface(self, seq, 0, &rng, &m, &err) || tcb_obj_write(path, m.verts, m.n_verts, m.faces, m.n_faces, &err))
        die("%s: %s", ops->name, err.msg);
    int nv = m.n_verts;
    tcb_uv_mesh_free(&m);
    return nv;
}

/* Removes the temporary directory dir and the files in it. */
static void remove_dir(const char *dir)
{
    char path[4096];
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name), remove(path);
    if (d) closedir(d);
    remove(dir);
}

/* Runs a PyTorch peer command: 0 with *ms and *rss_kib, PEER_SKIPPED when
 * it has no torch, -1 when it failed. */
static int run_peer(const char *cmd, double *ms, long *rss_kib)
{
    fflush(stdout);
    FILE *p = popen(cmd, "r");
    if (!p) return -1;
    int ok = fscanf(p, "%lf %ld", ms, rss_kib) == 2;
    int status = pclose(p);
    if (status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == PEER_SKIPPED)
        return PEER_SKIPPED;
    return ok && status == 0 ? 0 : -1;
}

static int time_torch(const options *o, const preset *pr, const char *method, double *ms, long *rss_kib)
{
    char cmd[8192];
    if ((size_t)snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s' %s %d %d %d %d %d %d", o->script, method, pr->C, P,
                         pr->M, N, o->iters, o->threads) >= sizeof cmd)
        return -1;
    return run_peer(cmd, ms, rss_kib);
}

static int time_cc_torch(const options *o, const cc_preset *pr, double *ms, long *rss_kib)
{
    char cmd[8192];
    const tcb_cc_dims *d = &pr->d;
    if ((size_t)snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s' %d %d %d %d %d %d %d %d", o->cc_script, d->C, d->Z,
                         d->H, d->L, pr->B, pr->N, o->iters, o->threads) >= sizeof cmd)
        return -1;
    return run_peer(cmd, ms, rss_kib);
}

static int time_neupig_torch(const options *o, const neupig_preset *pr, const char *obj, int frames, double *ms,
                             long *rss_kib)
{
    char cmd[8192];
    if ((size_t)snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s' '%s' %d %d %d %d %d %d %d", o->neupig_script, obj,
                         frames, pr->points, pr->levels, pr->features, pr->hidden, o->iters, o->threads) >= sizeof cmd)
        return -1;
    return run_peer(cmd, ms, rss_kib);
}

/* [rows][cols] of data as dir/name.npy. */
static int save_npy(const char *dir, const char *name, tcb_npy_dtype dtype, int rows, int cols, const void *data,
                    tcb_error *err)
{
    char path[128];
    const uint64_t shape[2] = {(uint64_t)rows, (uint64_t)cols};
    snprintf(path, sizeof path, "%s/%s.npy", dir, name);
    return tcb_npy_save(path, dtype, 2, shape, data, err);
}

/* The pdg peer's data and command: pdg's training of train_steps (self)
 * written to a new temporary directory dir, its clouds in the fields' cube
 * (points_<t>.npy) and its template as it started (template_verts.npy,
 * template_faces.npy); its keyframe, epochs and levels on the command
 * line. -1 when the command does not fit. */
static int pdg_peer(const options *o, const void *self, char *dir, char *cmd, size_t size)
{
    const void *state;
    const tcb_pcgrid_inputs *in = tcb_pcgrid_steps_inputs(self, &state);
    const tcb_pdg_trainer *t = state;
    const tcb_mesh *m = in->template_mesh;
    tcb_error err = {0};
    if (!mkdtemp(dir)) die("cannot create a temporary directory in /tmp");
    int rc = save_npy(dir, "template_verts", TCB_NPY_F4, m->n_verts, 3, m->verts, &err);
    if (!rc) rc = save_npy(dir, "template_faces", TCB_NPY_I4, m->n_faces, 3, m->faces, &err);
    for (int k = 0; !rc && k < in->clouds.T; k++) {
        char name[32];
        snprintf(name, sizeof name, "points_%d", k);
        rc = save_npy(dir, name, TCB_NPY_F4, in->clouds.n[k], 3, in->clouds.clouds[k], &err);
    }
    if (rc) die("pdg: %s", err.msg);
    return (size_t)snprintf(cmd, size, "/usr/bin/python3 '%s' '%s' %d %d %lld %d %d %d%s", o->pdg_script, dir,
                            in->clouds.T, in->key, t->sched.epochs, t->arch.levels, o->iters, o->threads,
                            o->losses ? " --losses" : "") < size ? 0 : -1;
}

static double peak_rss_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss / 1024.0;
}

static void print_header(const options *o)
{
    printf("training step, %d thread(s), mean of %d iteration(s) after 1 warm-up\n", o->threads, o->iters);
    printf("atlas (tcb_atlas_train_step), B=4 P=%d N=%d; GFLOP/it = 2 x minimal multiply-adds of\n"
           "  forward + backward (bench/atlas_bench.h):\n"
           "  encoder B*N*(3*64 + 64*128 + 128*C) + 2*B*C^2; per patch B*C*H1 + B*m*2*H1\n"
           "  + (1+nt)*B*m*(H1*H2 + H2*H3 + 3*H3), m = M/P, H1 = C+2, H2 = H1/2, H3 = H1/4,\n"
           "  nt = 2 tangents (dsr, mca) or 0 (atlasnet); backward ~2x (exact count in the header);\n"
           "cc (tcb_cc_train_step, six network calls; bench/cc_bench.h): 6 encoders\n"
           "  B*N*(3*64 + 64*128 + 128*C) + B*C*Z, 6 decoders B*(2Z*Z + Z*Z/2 + Z/2*K)\n"
           "  + B*N*sum_l(din^2 + din*dout); backward ~2x.\n"
           "neupig (one epoch: every frame; tcb_neupig_train_step): the MLP T*nv*(Din*H + H^2 + 7H),\n"
           "  backward 2x; grids, Chamfer and edge terms not counted.\n"
           "pdg (one epoch after the warm-up: every transition and chain; tcb_pdg_train_step): not counted (-).\n"
           "dynosurf (one step of stage 2, every frame): the blend network (nv + picks)*30*(6H + 4H^2 + H),\n"
           "  backward 2x; the transform network, samples, Chamfers and SDF terms not counted.\n"
           "Losses, nearest neighbours and Adam not counted.\n"
           "This machine's sgemm (OpenBLAS, %d thread(s), measured now): %.1f GFLOP/s on 2048^3;\n"
           "  %%sq: the step's GFLOP/s over it, %%shp: over sgemm on the step's dominant product (shape m x n x k);\n"
           "  ceiling: the torch/C a step of only its counted FLOPs at the 2048^3 rate would reach.\n",
           P, N, o->threads, o->sgemm_square);
    printf("%-6s %-9s %8s %9s %8s %5s %5s %10s %8s %7s %9s %9s  %s\n", "preset", "method", "GFLOP/it", "C ms/it",
           "GFLOP/s", "%sq", "%shp", "torch ms", "torch/C", "ceiling", "C RSS MiB", "torch MiB",
           "dominant product (sgemm GFLOP/s)");
}

/* One row: the C figures and the peer's (rc 0), or n/a; gflop < 0: not
 * counted (and no dominant product). The product's sgemm is measured here,
 * after the peer has finished. */
static void print_row(options *o, const char *preset, const char *method, double gflop, gemm_shape dominant,
                      double ms, int rc, double tms, long rss, const char *script)
{
    double gfs = gflop / ms * 1e3, c_rss = peak_rss_mib();
    if (gflop < 0) {
        printf("%-6s %-9s %8s %9.1f %8s %5s %5s", preset, method, "-", ms, "-", "-", "-");
    } else {
        double shape = sgemm_gflops(dominant);
        printf("%-6s %-9s %8.1f %9.1f %8.1f %4.0f%% %4.0f%%", preset, method, gflop, ms, gfs,
               100 * gfs / o->sgemm_square, 100 * gfs / shape);
        snprintf(o->dominant, sizeof o->dominant, "%dx%dx%d (%.1f)", dominant.m, dominant.n, dominant.k, shape);
    }
    if (rc == 0 && gflop >= 0)
        printf(" %10.1f %8.2f %7.2f %9.0f %9.0f", tms, tms / ms, tms / (gflop / o->sgemm_square * 1e3), c_rss,
               rss / 1024.0);
    else if (rc == 0)
        printf(" %10.1f %8.2f %7s %9.0f %9.0f", tms, tms / ms, "-", c_rss, rss / 1024.0);
    else
        printf(" %10s %8s %7s %9.0f %9s", "n/a", "n/a", "n/a", c_rss, "n/a");
    printf("  %s\n", gflop < 0 ? "-" : o->dominant);
    if (rc == PEER_SKIPPED && o->torch) {
        printf("PyTorch peer: unavailable (install python3-torch)\n");
        o->torch = 0;
    } else if (rc < 0) {
        printf("PyTorch peer: failed (%s)\n", script);
    }
    fflush(stdout);
}

static void run_row(options *o, const preset *pr, int k, const tcb_sequence *seq)
{
    double fwd, bwd, tms = 0;
    long rss = 0;
    bench_atlas_macs(pr->C, P, pr->M, 4, N, methods[k].nt, &fwd, &bwd);
    double ms = time_c(methods[k].name, pr->name, seq, o);
    int rc = o->torch ? time_torch(o, pr, methods[k].name, &tms, &rss) : PEER_SKIPPED;
    print_row(o, pr->name, methods[k].name, 2 * (fwd + bwd) * 1e-9, atlas_dominant(pr->C, pr->M, 4, methods[k].nt), ms,
              rc, tms, rss, o->script);
}

static void run_cc_row(options *o, const cc_preset *pr, const tcb_sequence *seq)
{
    double fwd, bwd, tms = 0;
    long rss = 0;
    bench_cc_macs(&pr->d, pr->B, pr->N, &fwd, &bwd);
    double ms = time_c("cc", pr->name, seq, o);
    int rc = o->torch ? time_cc_torch(o, pr, &tms, &rss) : PEER_SKIPPED;
    print_row(o, pr->name, "cc", 2 * (fwd + bwd) * 1e-9, (gemm_shape){pr->B * pr->N, pr->d.C, 128}, ms, rc, tms, rss,
              o->cc_script);
}

/* neupig at preset pr: its template, the method's, in a temporary OBJ for
 * the peer. */
static void run_neupig_row(options *o, const preset *p, const neupig_preset *pr, const tcb_sequence *seq)
{
    char dir[] = "/tmp/bench_train_step_XXXXXX", obj[64];
    if (!mkdtemp(dir)) die("cannot create a temporary directory in /tmp");
    snprintf(obj, sizeof obj, "%s/template.obj", dir);
    const tcb_method_ops *ops;
    void *self = create_at("neupig", p->name, &ops);
    double tms = 0, ms = time_steps(ops, self, seq, o);
    int nv = write_surface(ops, self, seq, obj);
    ops->destroy(self);
    long rss = 0;
    int rc = o->torch ? time_neupig_torch(o, pr, obj, seq->n_frames, &tms, &rss) : PEER_SKIPPED;
    remove_dir(dir);
    double fwd = (double)seq->n_frames * nv * ((double)pr->din * pr->hidden + (double)pr->hidden * pr->hidden + 7.0 * pr->hidden);
    print_row(o, p->name, "neupig", 2 * 3 * fwd * 1e-9, (gemm_shape){seq->n_frames * nv, pr->hidden, pr->hidden}, ms,
              rc, tms, rss, o->neupig_script);
}

/* --losses: LOSS_EPOCHS untimed epochs of pdg's train_steps, their loss
 * parts on stderr (the peer prints its first epochs'). */
static void print_losses(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, const options *o)
{
    tcb_fit_ctx ctx = {.seed = 1, .n_threads = o->threads};
    tcb_error err = {0};
    const void *state;
    fflush(stdout); /* after the header, in one log */
    for (int k = 0; k < LOSS_EPOCHS; k++) {
        if (ops->train_steps(self, seq, &ctx, 1, &err)) die("pdg: %s", err.msg);
        tcb_pcgrid_steps_inputs(self, &state);
        const tcb_pdg_trainer *t = state;
        fprintf(stderr, "pdg epoch %d, C:     total %.7g input %.7g pred %.7g edge %.7g template %.7g\n", k,
                t->last.total, t->last.input, t->last.pred, t->last.edge, t->template_loss);
    }
}

/* pdg at preset p, every term from the first epoch (the header); the peer
 * on the C training's data. */
static void run_pdg_row(options *o, const preset *p, const tcb_sequence *seq)
{
    const tcb_method_ops *ops;
    void *self = create_at("pdg", p->name, &ops);
    if (o->losses) print_losses(ops, self, seq, o);
    double tms = 0, ms = time_steps(ops, self, seq, o);
    char dir[] = "/tmp/bench_train_step_XXXXXX", cmd[8192];
    int rc = o->torch ? pdg_peer(o, self, dir, cmd, sizeof cmd) : PEER_SKIPPED;
    ops->destroy(self);
    long rss = 0;
    if (o->torch) {
        if (rc == 0) rc = run_peer(cmd, &tms, &rss);
        remove_dir(dir);
    }
    print_row(o, p->name, "pdg", -1, (gemm_shape){0, 0, 0}, ms, rc, tms, rss, o->pdg_script);
}

/* The dynosurf peer's data and command: the C training's stage 2 (self's
 * train_steps) written to a new temporary directory dir: every frame's
 * points and normals in DynoSurf's frame (points_<t>.npy, normals_<t>.npy),
 * the template (template_verts.npy, template_faces.npy), the grid and its
 * SDF (grid_verts.npy, grid_sdf.npy), the deformer's parameters as they
 * started (deformer.npy: control points, MLP_T, MLP_W); frames, keyframe,
 * samples and grid picks on the command line. -1 when it does not fit. */
static int dynosurf_peer(const options *o, const void *self, const float *deformer, char *dir, char *cmd, size_t size)
{
    const void *state;
    tcb_pcgrid_steps_inputs(self, &state);
    const dyno_trainer *t = state;
    const dyno_problem *p = t->p;
    tcb_error err = {0};
    if (!mkdtemp(dir)) die("cannot create a temporary directory in /tmp");
    int rc = save_npy(dir, "template_verts", TCB_NPY_F4, t->templ.n_verts, 3, t->templ.verts, &err);
    if (!rc) rc = save_npy(dir, "template_faces", TCB_NPY_I4, t->templ.n_faces, 3, t->templ.faces, &err);
    if (!rc) rc = save_npy(dir, "grid_verts", TCB_NPY_F4, p->grid->n_verts, 3, t->grid_v, &err);
    if (!rc) rc = save_npy(dir, "grid_sdf", TCB_NPY_F4, p->grid->n_verts, 1, t->grid_sdf, &err);
    if (!rc) rc = save_npy(dir, "deformer", TCB_NPY_F4, 1, (int)(t->n_params - t->n_shape), deformer, &err);
    for (int k = 0; !rc && k < p->T; k++) {
        char name[32];
        snprintf(name, sizeof name, "points_%d", k);
        rc = save_npy(dir, name, TCB_NPY_F4, p->n_pts[k], 3, p->pts[k], &err);
        snprintf(name, sizeof name, "normals_%d", k);
        if (!rc) rc = save_npy(dir, name, TCB_NPY_F4, p->n_pts[k], 3, p->normals[k], &err);
    }
    if (rc) die("dynosurf: %s", err.msg);
    return (size_t)snprintf(cmd, size, "/usr/bin/python3 '%s' '%s' %d %d %d %d %zu %d %d", o->dynosurf_script, dir,
                            p->T, p->key, t->s.samples, t->s.grid_samples, dyno_deformer_blend_offset(), o->iters,
                            o->threads) < size ? 0 : -1;
}

/* dynosurf at preset p: stage 2's step (its train_steps, main phase);
 * GFLOP/it counts the blend network over the template's vertices and the
 * grid picks, each against every control point (the transform network's
 * F·K rows are noise beside it), forward and twice that backward. */
static void run_dynosurf_row(options *o, const preset *p, const tcb_sequence *seq)
{
    const tcb_method_ops *ops;
    void *self = create_at("dynosurf", p->name, &ops);
    tcb_fit_ctx ctx = {.seed = 1, .n_threads = o->threads};
    tcb_error err = {0};
    /* a call of no steps builds the trainer, so that the deformer's start
     * can be kept for the peer before the timed steps move it */
    if (ops->train_steps(self, seq, &ctx, 0, &err)) die("dynosurf: %s", err.msg);
    const void *state;
    tcb_pcgrid_steps_inputs(self, &state);
    const dyno_trainer *t = state;
    size_t nd = t->n_params - t->n_shape;
    float *deformer = malloc(nd * sizeof *deformer);
    if (!deformer) die("dynosurf: out of memory");
    memcpy(deformer, t->params + t->n_shape, nd * sizeof *deformer);
    double tms = 0, ms = time_steps(ops, self, seq, o);
    long long rows = (long long)(t->templ.n_verts + t->s.grid_samples) * DYNO_CONTROL_POINTS;
    const double h = DYNO_DEFORM_WIDTH;
    double fwd = (double)rows * (DYNO_BLEND_IN * h + (DYNO_DEFORM_LAYERS - 2) * h * h + h);
    char dir[] = "/tmp/bench_train_step_XXXXXX", cmd[8192];
    int rc = o->torch ? dynosurf_peer(o, self, deformer, dir, cmd, sizeof cmd) : PEER_SKIPPED;
    ops->destroy(self);
    free(deformer);
    long rss = 0;
    if (o->torch) {
        if (rc == 0) rc = run_peer(cmd, &tms, &rss);
        remove_dir(dir);
    }
    print_row(o, p->name, "dynosurf", 2 * 3 * fwd * 1e-9, (gemm_shape){(int)rows, (int)h, (int)h}, ms, rc, tms, rss,
              o->dynosurf_script);
}

static void parse(int argc, char **argv, options *o)
{
    *o = (options){.iters = 5, .threads = omp_get_max_threads(), .torch = 1};
    bench_sibling_path(o->script, sizeof o->script, __FILE__, "train_step_torch.py");
    bench_sibling_path(o->cc_script, sizeof o->cc_script, __FILE__, "train_step_cc_torch.py");
    bench_sibling_path(o->neupig_script, sizeof o->neupig_script, __FILE__, "train_step_neupig_torch.py");
    bench_sibling_path(o->pdg_script, sizeof o->pdg_script, __FILE__, "train_step_pdg_torch.py");
    bench_sibling_path(o->dynosurf_script, sizeof o->dynosurf_script, __FILE__, "train_step_dynosurf_torch.py");
    for (int a = 1; a < argc; a++) {
        const char *v = a + 1 < argc ? argv[a + 1] : NULL;
        if (strcmp(argv[a], "--no-torch") == 0) o->torch = 0;
        else if (strcmp(argv[a], "--losses") == 0) o->losses = 1;
        else if (!v) die("bad argument %s (usage: top of bench/train_step.c)", argv[a]);
        else if (strcmp(argv[a], "--iters") == 0) o->iters = bench_positive_int(v, "--iters", "top of bench/train_step.c"), a++;
        else if (strcmp(argv[a], "--threads") == 0) o->threads = bench_positive_int(v, "--threads", "top of bench/train_step.c"), a++;
        else if (strcmp(argv[a], "--preset") == 0) o->preset = strcmp(v, "all") ? v : NULL, a++;
        else if (strcmp(argv[a], "--method") == 0) o->method = v, a++;
        else if (strcmp(argv[a], "--torch") == 0)
            snprintf(o->script, sizeof o->script, "%s", v), a++;
        else if (strcmp(argv[a], "--cc-torch") == 0)
            snprintf(o->cc_script, sizeof o->cc_script, "%s", v), a++;
        else if (strcmp(argv[a], "--neupig-torch") == 0)
            snprintf(o->neupig_script, sizeof o->neupig_script, "%s", v), a++;
        else if (strcmp(argv[a], "--pdg-torch") == 0)
            snprintf(o->pdg_script, sizeof o->pdg_script, "%s", v), a++;
        else if (strcmp(argv[a], "--dynosurf-torch") == 0)
            snprintf(o->dynosurf_script, sizeof o->dynosurf_script, "%s", v), a++;
        else die("bad argument %s (usage: top of bench/train_step.c)", argv[a]);
    }
    if (o->preset && strcmp(o->preset, "cpu") && strcmp(o->preset, "paper"))
        die("--preset must be paper, cpu or all");
    if (o->method && strcmp(o->method, "atlasnet") && strcmp(o->method, "dsr") && strcmp(o->method, "mca") &&
        strcmp(o->method, "cc") && strcmp(o->method, "neupig") && strcmp(o->method, "pdg") &&
        strcmp(o->method, "dynosurf"))
        die("--method must be atlasnet, dsr, mca, cc, neupig, pdg or dynosurf");
}

int main(int argc, char **argv)
{
    options o;
    parse(argc, argv, &o);
    /* before any work is created: the trainer sizes its pool from it */
    omp_set_num_threads(o.threads);
    tcb_sequence seq = {0};
    tcb_error err = {0};
    if (tcb_calibration_sequence(&seq, &err)) die("%s", err.msg);
    o.sgemm_square = sgemm_gflops((gemm_shape){2048, 2048, 2048});
    print_header(&o);
    for (size_t i = 0; i < sizeof presets / sizeof *presets; i++) {
        int want = !o.preset || strcmp(o.preset, presets[i].name) == 0;
        for (size_t k = 0; want && k < sizeof methods / sizeof *methods; k++)
            if (!o.method || strcmp(o.method, methods[k].name) == 0) run_row(&o, &presets[i], (int)k, &seq);
        if (want && (!o.method || strcmp(o.method, "cc") == 0)) run_cc_row(&o, &cc_presets[i], &seq);
        if (want && (!o.method || strcmp(o.method, "neupig") == 0)) run_neupig_row(&o, &presets[i], &neupig_presets[i], &seq);
        if (want && (!o.method || strcmp(o.method, "pdg") == 0)) run_pdg_row(&o, &presets[i], &seq);
        if (want && (!o.method || strcmp(o.method, "dynosurf") == 0)) run_dynosurf_row(&o, &presets[i], &seq);
    }
    tcb_sequence_free(&seq);
    /* last: its 0.5 GB would otherwise be every C row's peak RSS */
    printf("This machine's memory (c = 1.5a + b over 3 x 168 MB, %d thread(s), measured now): %.1f GB/s;\n"
           "  its ratio between thread counts bounds that of the steps' memory-bound passes.\n",
           o.threads, memory_triad());
    return 0;
}

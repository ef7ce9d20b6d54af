/* tcb_lap_solve against scipy.optimize.linear_sum_assignment, and a matrix
 * solver for the scipy cross-check test (tests/integration/test_lap_scipy.sh).
 *
 * Matrix file: int32 n_rows, int32 n_cols, then n_rows·n_cols float64,
 * row-major, little-endian (the machine's order on x86-64).
 *
 * usage: bench_lap --solve FILE
 *            prints "total <%.17g>" and a line with row_to_col[0..n)
 *        bench_lap [--reps R] [--scipy SCRIPT] [n ...]
 *            times both solvers on the same matrices (default n = 1000 2500
 *            5000): uniform [0,1) costs, and squared distances between two
 *            uniform 3-D clouds of n points (propagate_bijective's case).
 *            Best of R runs (default 1); scipy runs in /usr/bin/python3 via
 *            SCRIPT (default: lap_scipy.py next to this source file). */
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench_util.h"
#include "tcb/lap.h"
#include "tcb/rng.h"

#define die(...) bench_die("bench_lap", __VA_ARGS__)

/* Returns the [n_rows][n_cols] matrix, malloc'ed; exits on a malformed file. */
static double *read_matrix(const char *path, int *n_rows, int *n_cols)
{
    FILE *f = fopen(path, "rb");
    if (!f) die("cannot open %s", path);
    int32_t hdr[2];
    if (fread(hdr, sizeof hdr, 1, f) != 1 || hdr[0] < 0 || hdr[1] < 0)
        die("%s: bad header (want int32 n_rows, n_cols ≥ 0)", path);
    size_t count = (size_t)hdr[0] * (size_t)hdr[1];
    double *c = malloc((count ? count : 1) * sizeof *c);
    if (!c) die("%s: no memory for the matrix", path);
    if (fread(c, sizeof *c, count, f) != count || fgetc(f) != EOF)
        die("%s: size does not match the header", path);
    fclose(f);
    *n_rows = hdr[0], *n_cols = hdr[1];
    return c;
}

static void write_matrix(const char *path, const double *c, int n)
{
    FILE *f = fopen(path, "wb");
    int32_t hdr[2] = {n, n};
    size_t count = (size_t)n * n;
    if (!f || fwrite(hdr, sizeof hdr, 1, f) != 1 || fwrite(c, sizeof *c, count, f) != count ||
        fclose(f) != 0)
        die("cannot write %s", path);
}

static int solve_file(const char *path)
{
    int n_rows, n_cols;
    double *c = read_matrix(path, &n_rows, &n_cols);
    int32_t *sol = malloc(((size_t)n_rows + 1) * sizeof *sol);
    if (!sol) die("%s: no memory", path);
    tcb_error err = {0};
    double total;
    int rc = tcb_lap_solve(c, n_rows, n_cols, sol, &total, &err);
    if (rc) {
        fprintf(stderr, "bench_lap: %s: %s\n", path, err.msg);
        free(c), free(sol);
        return tcb_status_exit_code(rc);
    }
    printf("total %.17g\n", total);
    for (int i = 0; i < n_rows; i++) printf(i ? " %d" : "%d", sol[i]);
    printf("\n");
    free(c), free(sol);
    return 0;
}

/* cost [n][n]: uniform [0,1) ("uniform") or |p_i − q_j|² for two uniform
 * clouds in the unit cube ("sqdist"). */
static void fill(double *c, int n, int sqdist, tcb_rng *rng)
{
    if (!sqdist) {
        for (size_t k = 0; k < (size_t)n * n; k++) c[k] = tcb_rng_uniform(rng);
        return;
    }
    double *p = malloc((size_t)n * 6 * sizeof *p);
    if (!p) die("no memory");
    const double *q = p + 3 * (size_t)n;
    for (int k = 0; k < 6 * n; k++) p[k] = tcb_rng_uniform(rng);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double s = 0.0;
            for (int a = 0; a < 3; a++) {
                double t = p[3 * i + a] - q[3 * j + a];
                s += t * t;
            }
            c[(size_t)i * n + j] = s;
        }
    free(p);
}

/* Best of reps; *total from the last run. */
static double time_tcbench(const double *c, int n, int reps, int32_t *sol, double *total)
{
    double best = 1e300;
    for (int r = 0; r < reps; r++) {
        tcb_error err = {0};
        double t0 = bench_now_ms();
        if (tcb_lap_solve(c, n, n, sol, total, &err)) die("%s", err.msg);
        double t = bench_now_ms() - t0;
        if (t < best) best = t;
    }
    return best;
}

/* Runs the scipy script on a matrix file; returns 0 and fills ms, total. */
static int time_scipy(const char *script, const char *path, int reps, double *ms, double *total)
{
    char cmd[8192];
    if ((size_t)snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s' '%s' %d", script, path, reps) >=
        sizeof cmd)
        return -1;
    FILE *p = popen(cmd, "r");
    if (!p) return -1;
    int ok = fscanf(p, "%lf %lf", ms, total) == 2;
    return pclose(p) == 0 && ok ? 0 : -1;
}

static void bench(int *sizes, int nsizes, int reps, const char *script)
{
    char path[] = "/tmp/bench_lap_XXXXXX";
    int fd = mkstemp(path);
    if (fd < 0) die("cannot create a temporary file");
    close(fd);
    printf("dense LAP, best of %d, ms per solve (scipy via %s)\n", reps, script);
    printf("%6s %8s %12s %12s %14s %12s\n", "n", "costs", "tcbench ms", "scipy ms",
           "scipy/tcbench", "rel. diff");
    for (int s = 0; s < nsizes; s++) {
        int n = sizes[s];
        double *c = malloc((size_t)n * n * sizeof *c);
        int32_t *sol = malloc((size_t)n * sizeof *sol);
        if (!c || !sol) die("no memory");
        for (int sq = 0; sq < 2; sq++) {
            tcb_rng rng;
            tcb_rng_seed_stream(&rng, (uint64_t)n, sq ? "bench/lap/sqdist" : "bench/lap/uniform");
            fill(c, n, sq, &rng);
            double total, st, sms;
            double ms = time_tcbench(c, n, reps, sol, &total);
            write_matrix(path, c, n);
            if (time_scipy(script, path, reps, &sms, &st) == 0)
                printf("%6d %8s %12.1f %12.1f %14.2f %12.1e\n", n, sq ? "sqdist" : "uniform", ms,
                       sms, sms / ms, (total - st) / st);
            else
                printf("%6d %8s %12.1f %12s %14s %12s\n", n, sq ? "sqdist" : "uniform", ms, "n/a",
                       "n/a", "n/a");
            fflush(stdout);
        }
        free(c), free(sol);
    }
    unlink(path);
}

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--solve") == 0) return solve_file(argv[2]);
    int reps = 1, nsizes = 0, sizes[32];
    char script[4096];
    bench_sibling_path(script, sizeof script, __FILE__, "lap_scipy.py");
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--reps") == 0 && a + 1 < argc) reps = bench_positive_int(argv[++a], "--reps", "top of bench/bench_lap.c");
        else if (strcmp(argv[a], "--scipy") == 0 && a + 1 < argc)
            snprintf(script, sizeof script, "%s", argv[++a]);
        else if (atoi(argv[a]) > 0 && nsizes < 32) sizes[nsizes++] = atoi(argv[a]);
        else die("bad argument %s (usage: top of bench/bench_lap.c)", argv[a]);
    }
    if (nsizes == 0) sizes[0] = 1000, sizes[1] = 2500, sizes[2] = 5000, nsizes = 3;
    bench(sizes, nsizes, reps < 1 ? 1 : reps, script);
    return 0;
}

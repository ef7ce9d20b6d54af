#define _XOPEN_SOURCE 700 /* nftw */
#include "testutil.h"

#include "methods/pdg/field.h"
#include "tcb/rng.h"

#include <dirent.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

void tu_make_tmpdir(char *out, size_t size)
{
    const char *base = getenv("TMPDIR");
    if (!base || !*base) base = "/tmp";
    if ((size_t)snprintf(out, size, "%s/tcbench-test-XXXXXX", base) >= size || !mkdtemp(out)) {
        fprintf(stderr, "cannot create a temporary directory under %s\n", base);
        abort();
    }
}

void tu_write_text(const char *dir, const char *name, const char *text, char *out, size_t size)
{
    if ((size_t)snprintf(out, size, "%s/%s", dir, name) >= size) abort();
    FILE *f = fopen(out, "wb");
    if (!f) {
        perror(out);
        abort();
    }
    fputs(text, f);
    fclose(f);
}

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(path);
}

void tu_remove_tree(const char *dir)
{
    nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

int tu_setup_tmpdir(void **state)
{
    static char dir[4096]; /* one test runs at a time within a program */
    tu_make_tmpdir(dir, sizeof dir);
    *state = dir;
    return 0;
}

int tu_teardown_tmpdir(void **state)
{
    tu_remove_tree(*state);
    return 0;
}

const char *tu_shared_data(void)
{
    struct stat st;
    return stat(TCB_SHARED_DATA, &st) == 0 && S_ISDIR(st.st_mode) ? TCB_SHARED_DATA : NULL;
}

static void *zeroed(size_t n, size_t size)
{
    void *p = calloc(n ? n : 1, size);
    if (!p) {
        fprintf(stderr, "out of memory (%zu × %zu bytes)\n", n, size);
        abort();
    }
    return p;
}

float *tu_falloc(size_t n) { return zeroed(n, sizeof(float)); }

double *tu_dalloc(size_t n) { return zeroed(n, sizeof(double)); }

double *tu_to_double(const float *x, size_t n)
{
    double *d = tu_dalloc(n);
    for (size_t i = 0; i < n; i++) d[i] = x[i];
    return d;
}

void tu_fill_uniform(tcb_rng *r, float *x, size_t n, double lo, double hi)
{
    for (size_t i = 0; i < n; i++) x[i] = (float)(lo + (hi - lo) * tcb_rng_uniform(r));
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static uint64_t directed(int32_t from, int32_t to) { return (uint64_t)(uint32_t)from << 32 | (uint32_t)to; }

int tu_closed_oriented(const int32_t *faces, int nf)
{
    size_t n = 3 * (size_t)nf;
    uint64_t *e = malloc((n ? n : 1) * sizeof *e);
    if (!e) abort();
    for (int f = 0; f < nf; f++)
        for (int i = 0; i < 3; i++) e[3 * f + i] = directed(faces[3 * f + i], faces[3 * f + (i + 1) % 3]);
    qsort(e, n, sizeof *e, cmp_u64);
    int ok = 1;
    for (size_t i = 1; ok && i < n; i++) ok = e[i] != e[i - 1];
    for (size_t i = 0; ok && i < n; i++) {
        uint64_t rev = directed((int32_t)(e[i] & 0xffffffffu), (int32_t)(e[i] >> 32));
        ok = bsearch(&rev, e, n, sizeof *e, cmp_u64) != NULL;
    }
    free(e);
    return ok;
}

int tu_for_each_json(const char *dir, void (*fn)(const char *path, void *arg), void *arg)
{
    DIR *d = opendir(dir);
    if (!d) {
        fprintf(stderr, "%s: cannot open\n", dir);
        abort();
    }
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) {
        char path[8192];
        size_t len = strlen(e->d_name);
        if (e->d_name[0] == '.') continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (e->d_type == DT_DIR) {
            n += tu_for_each_json(path, fn, arg);
        } else if (len >= 6 && !strcmp(e->d_name + len - 5, ".json")) {
            fn(path, arg);
            n++;
        }
    }
    closedir(d);
    return n;
}

void tu_ref_trilinear(const double *values, int r, int F, const double p[3], double *out)
{
    double u[3];
    int i0[3];
    for (int a = 0; a < 3; a++) {
        u[a] = fmin(fmax((p[a] + 1.0) * 0.5 * (r - 1), 0.0), r - 1.0);
        i0[a] = (int)floor(u[a]);
    }
    for (int f = 0; f < F; f++) out[f] = 0.0;
    for (int c = 0; c < 8; c++) {
        int idx[3] = {i0[0] + (c & 1), i0[1] + ((c >> 1) & 1), i0[2] + (c >> 2)};
        double w = 1.0;
        for (int a = 0; a < 3; a++) w *= (idx[a] == i0[a]) ? 1.0 - (u[a] - i0[a]) : u[a] - i0[a];
        if (idx[0] >= r || idx[1] >= r || idx[2] >= r) continue;
        const double *v = values + ((size_t)(idx[2] * r + idx[1]) * r + idx[0]) * F;
        for (int f = 0; f < F; f++) out[f] += w * v[f];
    }
}

double tu_ref_chamfer_way(const double *q, int nq, const double *to, int nt, const double *w_in, double *w_out)
{
    double sum = 0.0;
    for (int i = 0; i < nq; i++) {
        double best = INFINITY;
        for (int j = 0; j < nt; j++) {
            double s = 0.0;
            for (int k = 0; k < 3; k++) s += (q[3 * i + k] - to[3 * j + k]) * (q[3 * i + k] - to[3 * j + k]);
            best = fmin(best, s);
        }
        double w = w_in ? w_in[i] : exp(-best * best / (2.0 * 0.3 * 0.3));
        if (w_out) w_out[i] = w;
        sum += w * best;
    }
    return sum;
}

double tu_central(double (*f)(const void *ctx), const void *ctx, double *z, double h)
{
    double keep = *z;
    *z = keep + h;
    double lp = f(ctx);
    *z = keep - h;
    double lm = f(ctx);
    *z = keep;
    return (lp - lm) / (2.0 * h);
}

void tu_ref_cayley(const double r[3], double R[9])
{
    const double K[9] = {0, -r[2], r[1], r[2], 0, -r[0], -r[1], r[0], 0};
    double M[9], P[9], adj[9];
    for (int i = 0; i < 9; i++) M[i] = (i % 4 == 0) - K[i], P[i] = (i % 4 == 0) + K[i];
    for (int i = 0; i < 3; i++) /* adj[i][j] = cofactor of M[j][i] */
        for (int j = 0; j < 3; j++) {
            int a0 = (j + 1) % 3, a1 = (j + 2) % 3, b0 = (i + 1) % 3, b1 = (i + 2) % 3;
            adj[3 * i + j] = M[3 * a0 + b0] * M[3 * a1 + b1] - M[3 * a0 + b1] * M[3 * a1 + b0];
        }
    double det = M[0] * adj[0] + M[1] * adj[3] + M[2] * adj[6];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            R[3 * i + j] = 0.0;
            for (int k = 0; k < 3; k++) R[3 * i + j] += adj[3 * i + k] * P[3 * k + j] / det;
        }
}

void tu_ref_pdg_step(const struct tcb_pdg_fields *f, const double *V, int g, const double x[3], const double x0[3],
                     const double *A, double *A_out, double y[3])
{
    double s[6] = {0}, o[6], R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, T[12], out[12];
    for (int l = 0; l < f->levels; l++) {
        tu_ref_trilinear(V + f->off[l] + (size_t)g * f->r[l] * f->r[l] * f->r[l] * f->C, f->r[l], f->C, x, o);
        for (int c = 0; c < f->C; c++) s[c] += o[c] / f->levels;
    }
    if (f->C == 6) tu_ref_cayley(s, R);
    for (int a = 0; a < 3; a++) {
        for (int b = 0; b < 3; b++) T[4 * a + b] = R[3 * a + b];
        T[4 * a + 3] = 0.1 * tanh(s[f->C - 3 + a]);
    }
    for (int a = 0; a < 3; a++) /* A' = A · [T; 0 0 0 1] */
        for (int b = 0; b < 4; b++) {
            double sum = A ? (b == 3) * A[4 * a + 3] : T[4 * a + b];
            for (int k = 0; A && k < 3; k++) sum += A[4 * a + k] * T[4 * k + b];
            out[4 * a + b] = sum;
        }
    for (int a = 0; a < 3; a++) y[a] = out[4 * a] * x0[0] + out[4 * a + 1] * x0[1] + out[4 * a + 2] * x0[2] + out[4 * a + 3];
    if (A_out) memcpy(A_out, out, sizeof out);
}

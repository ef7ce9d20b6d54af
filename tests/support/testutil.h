/* Small helpers shared by the unit tests. */
#ifndef TCB_TESTUTIL_H
#define TCB_TESTUTIL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* cmocka 1.1 has no floating-point assertion: |a − b| ≤ tol, printing both. */
#define assert_near(a, b, tol)                                                                     \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        if (!(fabs(a_ - b_) <= (tol))) fail_msg("%s = %.17g, expected %.17g", #a, a_, b_);         \
    } while (0)

/* Creates a fresh directory under $TMPDIR (or /tmp) and writes its path to
 * out; aborts the test program on failure. */
void tu_make_tmpdir(char *out, size_t size);

/* Writes text to dir/name (creating it); returns the full path in out. */
void tu_write_text(const char *dir, const char *name, const char *text, char *out,
                   size_t size);

/* cmocka setup/teardown giving each test a fresh temporary directory as
 * *state (a char *), removed afterwards. */
int tu_setup_tmpdir(void **state);
int tu_teardown_tmpdir(void **state);

/* Calls fn on every *.json under dir, subdirectories included (dot names
 * skipped); returns how many. */
int tu_for_each_json(const char *dir, void (*fn)(const char *path, void *arg), void *arg);
/* rm -rf of a directory made by tu_make_tmpdir. */
void tu_remove_tree(const char *dir);

/* Path of the shared real data (../shared/data), or NULL when absent. */
const char *tu_shared_data(void);

/* Zeroed arrays of n floats / doubles (at least one element); abort on
 * out of memory. */
float *tu_falloc(size_t n);
double *tu_dalloc(size_t n);

/* A double copy of x[0..n). */
double *tu_to_double(const float *x, size_t n);

/* x[i] = U(lo, hi) from r, in order. */
struct tcb_rng;
void tu_fill_uniform(struct tcb_rng *r, float *x, size_t n, double lo, double hi);

/* The trilinear sample out [F] of a lattice values [r³][F] (x fastest) at
 * the point p, in double, written from PyTorch's grid_sample rules
 * (align_corners=True, padding_mode="border"): u = (p+1)/2·(r−1) clamped
 * to [0, r−1], the corners floor(u) and floor(u)+1, a corner past the last
 * node weighing nothing; r = 1 is the one node's value. The reference of
 * neural/lattice.c's tests and of the methods sampling lattices. */
void tu_ref_trilinear(const double *values, int r, int F, const double p[3], double *out);

/* One direction of the robust Chamfer (neural/robust_chamfer.h), in
 * double with brute-force nearest neighbours: Σ_q w_q · min_t |q − t|²,
 * w_q the Welsch weight exp(−s²/(2·0.3²)) of q's squared distance s. With
 * w_in the weights are those (held, as the method holds them in its
 * gradient); else they are computed, and stored into w_out when it is not
 * NULL. */
double tu_ref_chamfer_way(const double *q, int nq, const double *to, int nt, const double *w_in, double *w_out);

/* The central difference (f(ctx) at *z + h − at *z − h) / 2h: f's
 * derivative in *z, one of the numbers it reads through ctx (restored). */
double tu_central(double (*f)(const void *ctx), const void *ctx, double *z, double h);

/* R [3][3] row-major = (I − K)⁻¹(I + K), K = [r]× (K v = r × v), in double
 * by the adjugate of I − K: the Cayley map as defined, the reference of
 * PDG's closed form. */
void tu_ref_cayley(const double r[3], double R[9]);

/* PDG's step of one point through field g of f (methods/pdg/field.h), in
 * double, as the release composes its transforms: s [C] the mean of field
 * g's levels sampled at x (tu_ref_trilinear); R the identity (C = 3) or
 * tu_ref_cayley(s[0..2]) (C = 6); A' = A · [R | 0.1 tanh(s_t)], A [12]
 * row-major 3×4 (NULL: the identity); y = A' x0. A_out [12] may be NULL. */
struct tcb_pdg_fields;
void tu_ref_pdg_step(const struct tcb_pdg_fields *f, const double *V, int g, const double x[3], const double x0[3],
                     const double *A, double *A_out, double y[3]);

/* 1 when nf triangles form closed surfaces, consistently oriented: every
 * directed edge occurs once and its reverse occurs too (so each undirected
 * edge has exactly two faces, wound opposite ways); 0 otherwise. */
int tu_closed_oriented(const int32_t *faces, int nf);

#endif

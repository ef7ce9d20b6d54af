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

/* 1 when nf triangles form closed surfaces, consistently oriented: every
 * directed edge occurs once and its reverse occurs too (so each undirected
 * edge has exactly two faces, wound opposite ways); 0 otherwise. */
int tu_closed_oriented(const int32_t *faces, int nf);

#endif

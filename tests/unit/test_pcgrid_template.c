/* methods/pcgrid/template.c: the two templates on a synthetic body's
 * frame, normalised into the cube as the methods do — Neu-PiG's (the
 * Poisson surface decimated) and PDG's (remeshed toward the mean edge
 * length first, the decimation accepted once its Chamfer to the remeshed
 * surface is below 5e-4) — both within the budget, closed and outward,
 * on the body's surface, and not the same mesh; and a check that cannot
 * pass reported after its rounds. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/pcgrid/prepare.h"
#include "methods/pcgrid/template.h"
#include "tcb/geometry.h"
#include "tcb/metrics.h"
#include "tcb/rng.h"
#include "tcb/synth.h"
#include "testutil.h"

enum { POINTS = 5000, FACES = 4000 };

typedef struct body {
    tcb_sequence seq;
    tcb_pcgrid_frame_map map;
    float *cloud, *dense; /* POINTS and 50 000 samples of frame 0, in the cube */
} body;

static int setup(void **state)
{
    body *b = calloc(1, sizeof *b);
    tcb_error err = {0};
    if (!b || tcb_synth_generate("quadruped_walk", 0, 1, &b->seq, &err)) return -1;
    b->cloud = tu_falloc(3 * POINTS);
    b->dense = tu_falloc(3 * 50000);
    tcb_rng r;
    tcb_rng_seed(&r, 3);
    if (tcb_sample_surface(b->seq.verts, b->seq.faces, b->seq.n_faces, POINTS, &r, b->cloud, &err) ||
        tcb_sample_surface(b->seq.verts, b->seq.faces, b->seq.n_faces, 50000, &r, b->dense, &err))
        return -1;
    const float *clouds[1] = {b->cloud};
    int n[1] = {POINTS};
    if (tcb_pcgrid_frame_map_of(clouds, n, 1, &b->map, &err)) return -1;
    tcb_pcgrid_map_points(&b->map, b->cloud, POINTS, b->cloud);
    tcb_pcgrid_map_points(&b->map, b->dense, 50000, b->dense);
    *state = b;
    return 0;
}

static int teardown(void **state)
{
    body *b = *state;
    tcb_sequence_free(&b->seq);
    free(b->cloud), free(b->dense);
    free(b);
    return 0;
}

/* Edge lengths: their coefficient of variation (std / mean). */
static double edge_spread(const tcb_mesh *m)
{
    double s = 0, s2 = 0;
    int n = 0;
    for (int f = 0; f < m->n_faces; f++)
        for (int k = 0; k < 3; k++) {
            const float *p = m->verts + 3 * m->faces[3 * f + k], *q = m->verts + 3 * m->faces[3 * f + (k + 1) % 3];
            double d = sqrt(((double)p[0] - q[0]) * (p[0] - q[0]) + ((double)p[1] - q[1]) * (p[1] - q[1]) +
                            ((double)p[2] - q[2]) * (p[2] - q[2]));
            s += d, s2 += d * d, n++;
        }
    double mean = s / n;
    return sqrt(s2 / n - mean * mean) / mean;
}

static void build_ok(const body *b, const tcb_pcgrid_template_spec *spec, tcb_mesh *t)
{
    tcb_error err = {0};
    memset(t, 0, sizeof *t);
    if (tcb_pcgrid_template_build(&b->seq, 0, &b->map, b->cloud, POINTS, spec, t, &err)) fail_msg("%s", err.msg);
    double cd;
    float *samples = tu_falloc(3 * 50000);
    tcb_rng r;
    tcb_rng_seed(&r, 9);
    if (tcb_sample_surface(t->verts, t->faces, t->n_faces, 50000, &r, samples, &err) ||
        tcb_chamfer(samples, 50000, b->dense, 50000, &cd, &err))
        fail_msg("%s", err.msg);
    print_message("%s: %d vertices, %d faces, edge length std/mean %.3f, Chamfer to the body %.2e\n",
                  spec->remesh_iterations ? "PDG" : "Neu-PiG", t->n_verts, t->n_faces, edge_spread(t), cd);
    assert_true(t->n_faces <= spec->template_faces && t->n_faces > spec->template_faces * 9 / 10);
    assert_true(tu_closed_oriented(t->faces, t->n_faces));
    assert_true(cd < 2e-4);
    free(samples);
}

static void test_both_templates(void **state)
{
    body *b = *state;
    tcb_pcgrid_template_spec neupig = {.gt_normals = 1, .poisson_depth = 8, .template_faces = FACES};
    tcb_pcgrid_template_spec pdg = neupig;
    pdg.remesh_iterations = 5, pdg.check_samples = 10000, pdg.max_rounds = 10, pdg.check_chamfer = 5e-4;
    tcb_mesh a, c;
    build_ok(b, &neupig, &a);
    build_ok(b, &pdg, &c);
    /* The remeshing feeds the decimation, and the decimation is the
     * template (the release throws its last remeshing away): PDG's edges
     * are no more even than Neu-PiG's (measured std/mean 0.454 and 0.436),
     * but the meshes differ. */
    assert_true(a.n_verts != c.n_verts || memcmp(a.verts, c.verts, 3 * sizeof(float) * (size_t)a.n_verts));
    tcb_mesh_free(&a), tcb_mesh_free(&c);
}

static void test_check_that_cannot_pass(void **state)
{
    body *b = *state;
    tcb_pcgrid_template_spec pdg = {.gt_normals = 1, .poisson_depth = 6, .template_faces = 40, .remesh_iterations = 1,
                                    .check_samples = 2000, .max_rounds = 2, .check_chamfer = 1e-9};
    tcb_mesh t = {0, 0, NULL, NULL};
    tcb_error err = {0};
    assert_int_equal(tcb_pcgrid_template_build(&b->seq, 0, &b->map, b->cloud, POINTS, &pdg, &t, &err), TCB_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "after 2 rounds"));
    assert_null(t.verts);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_both_templates),
                                       cmocka_unit_test(test_check_that_cannot_pass)};
    return cmocka_run_group_tests(tests, setup, teardown);
}

/* The real sequences in ../shared/data (skipped when absent). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>
#include <stdio.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/geometry.h"
#include "tcb/sequence.h"
#include "testutil.h"

/* Reads <shared>/<rel>, or skips the test when the data is absent. */
static void read_or_skip(const char *rel, tcb_sequence *s)
{
    const char *data = tu_shared_data();
    if (!data) {
        printf("skipped: ../shared/data absent\n");
        skip();
    }
    char dir[TCB_PATH_MAX];
    snprintf(dir, sizeof dir, "%s/%s", data, rel);
    tcb_error err = {0};
    int rc = tcb_sequence_read_objdir(dir, s, &err);
    if (rc) fail_msg("%s", err.msg);
}

/* Every face refers to real vertices and the surface has positive area. */
static void assert_sane(const tcb_sequence *s)
{
    for (size_t i = 0; i < 3 * (size_t)s->n_faces; i++)
        assert_true(s->faces[i] >= 0 && s->faces[i] < s->n_verts);
    for (int f = 0; f < s->n_frames; f++) assert_true(tcb_mesh_area(tcb_seq_frame(s, f), s->faces, s->n_faces) > 0);
}

static void test_cat_walk(void **state)
{
    (void)state;
    tcb_sequence s;
    read_or_skip("anim/cat_walk", &s);
    assert_string_equal(s.name, "cat_walk");
    assert_int_equal(s.n_frames, 35);
    assert_int_equal(s.n_verts, 1297);
    /* 1175 quads, 59 triangles, 37 pentagons, 14 hexagons, fanned. */
    assert_int_equal(s.n_faces, 1175 * 2 + 59 + 37 * 3 + 14 * 4);
    assert_sane(&s);
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_normalize(&s, TCB_NORM_FIRST_FRAME, &err), TCB_OK);
    assert_int_equal(tcb_sequence_sample_pools(&s, 1000, 0, &err), TCB_OK);
    tcb_sequence_free(&s);
}

static void test_crane(void **state)
{
    (void)state;
    tcb_sequence s;
    read_or_skip("ama/crane", &s);
    assert_int_equal(s.n_frames, 175);
    assert_int_equal(s.n_verts, 10002);
    assert_int_equal(s.n_faces, 20000);
    assert_sane(&s);
    tcb_sequence_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cat_walk),
        cmocka_unit_test(test_crane),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/* OBJ reader: every accepted form, every rejected input, and the writer. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>
#include <stdio.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/mesh_io.h"
#include "testutil.h"

static int read_text(const char *dir, const char *text, tcb_mesh *m, tcb_error *err, char *path)
{
    tu_write_text(dir, "m.obj", text, path, TCB_PATH_MAX);
    return tcb_obj_read(path, m, err);
}

static void assert_faces(const tcb_mesh *m, const int32_t *want, int nf)
{
    assert_int_equal(m->n_faces, nf);
    assert_memory_equal(m->faces, want, sizeof(int32_t) * 3 * (size_t)nf);
}

static const char square[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

static void test_index_forms(void **state)
{
    /* Same triangle (1 2 3) written in each reference form. */
    static const char *const forms[] = {"f 1 2 3\n", "f 1/1 2/2 3/3\n", "f 1//1 2//1 3//1\n",
                                        "f 1/1/1 2/2/1 3/3/1\n", "f -4 -3 -2\n", "f 1/1 -3/2 3//1\n"};
    const int32_t want[3] = {0, 1, 2};
    for (size_t i = 0; i < sizeof forms / sizeof forms[0]; i++) {
        char text[256], path[TCB_PATH_MAX];
        snprintf(text, sizeof text, "%s%s", square, forms[i]);
        tcb_mesh m;
        tcb_error err = {0};
        assert_int_equal(read_text(*state, text, &m, &err, path), TCB_OK);
        assert_int_equal(m.n_verts, 4);
        assert_faces(&m, want, 1);
        tcb_mesh_free(&m);
    }
}

static void test_polygons_fan(void **state)
{
    char path[TCB_PATH_MAX];
    tcb_mesh m;
    tcb_error err = {0};
    const char *text = "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\n"
                       "f -5 -4 -3 -2 -1\n" /* the pentagon 1 2 3 4 5 */
                       "f 1 2 3 4\n";
    assert_int_equal(read_text(*state, text, &m, &err, path), TCB_OK);
    const int32_t want[5 * 3] = {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 1, 2, 0, 2, 3};
    assert_faces(&m, want, 5);
    tcb_mesh_free(&m);
}

static void test_tolerated_syntax(void **state)
{
    char path[TCB_PATH_MAX];
    tcb_mesh m;
    tcb_error err = {0};
    /* Comments, blank lines, CRLF, tabs, ignored statements, a w
     * coordinate, vertex colours and a trailing comment. */
    const char *text = "# header\r\n"
                       "mtllib a.mtl\r\n"
                       "o thing\r\n"
                       "\r\n"
                       "v 1.5 -2e-3 +3\r\n"
                       "v\t4 5 6 1.0\r\n"
                       "v 7 8 9 0.1 0.2 0.3 # coloured\r\n"
                       "   \r\n"
                       "vt 0.5 0.5\r\nvn 0 0 1\r\ng group\r\ns off\r\nusemtl skin\r\nl 1 2\r\n"
                       "f 1 2 3 # tri\r\n"
                       "f 3 2 1"; /* no final newline */
    assert_int_equal(read_text(*state, text, &m, &err, path), TCB_OK);
    const float want_v[9] = {1.5f, -2e-3f, 3, 4, 5, 6, 7, 8, 9};
    assert_int_equal(m.n_verts, 3);
    assert_memory_equal(m.verts, want_v, sizeof want_v);
    const int32_t want_f[6] = {0, 1, 2, 2, 1, 0};
    assert_faces(&m, want_f, 2);
    tcb_mesh_free(&m);
}

static void test_face_before_vertices(void **state)
{
    /* Positive indices may refer to vertices defined later in the file. */
    char path[TCB_PATH_MAX];
    tcb_mesh m;
    tcb_error err = {0};
    assert_int_equal(read_text(*state, "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", &m, &err, path), TCB_OK);
    assert_int_equal(m.n_faces, 1);
    tcb_mesh_free(&m);
}

typedef struct bad_case {
    const char *text;
    int line;         /* expected in the message as ":<line>:" */
    const char *why;  /* and this phrase */
} bad_case;

#define TRI "v 0 0 0\nv 1 0 0\nv 0 1 0\n" /* lines 1-3 */

static void test_bad_inputs(void **state)
{
    static const bad_case cases[] = {
        {"v 1 2 x\n" TRI "f 1 2 3\n", 1, "bad number"},
        {TRI "v 1 2\nf 1 2 3\n", 4, "needs 3 coordinates"},
        {TRI "v 1 2 3abc\nf 1 2 3\n", 4, "bad number"},
        {TRI "\nv nan 0 0\nf 1 2 3\n", 5, "NaN or infinite"},
        {"v -inf 0 0\n" TRI "f 1 2 3\n", 1, "NaN or infinite"},
        {"v 1e39 0 0\n" TRI "f 1 2 3\n", 1, "NaN or infinite"}, /* overflows float */
        {TRI "f 0 1 2\n", 4, "index 0"},
        {TRI "f 1 2 4\n# end\n", 4, "out of range"},
        {TRI "f -4 -1 -2\n", 4, "out of range"},
        {TRI "f 99999999999999999999 1 2\n", 4, "out of range"},
        {TRI "f 1 2\n", 4, "needs at least 3"},
        {TRI "f 1/a 2 3\n", 4, "bad index"},
        {TRI "f 1.5 2 3\n", 4, "bad index"},
        {TRI "f 1/1/1/1 2 3\n", 4, "bad index"},
        {TRI "f 1// 2 3\n", 4, "bad index"},
        {"v 0 0 0\nhello world\n", 2, "unsupported statement 'hello'"},
        {TRI, 3, "without any face"},
        {"# nothing here\n\n", 2, "without any vertex"},
        {"", 1, "without any vertex"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[TCB_PATH_MAX], where[TCB_PATH_MAX + 32];
        tcb_mesh m;
        tcb_error err = {0};
        int rc = read_text(*state, cases[i].text, &m, &err, path);
        if (rc != TCB_ERR_INPUT) fail_msg("case %zu: rc %d (%s)", i, rc, err.msg);
        snprintf(where, sizeof where, "%s:%d:", path, cases[i].line);
        if (!strstr(err.msg, where) || !strstr(err.msg, cases[i].why))
            fail_msg("case %zu: '%s' lacks '%s' or '%s'", i, err.msg, where, cases[i].why);
        assert_null(m.verts);
        assert_null(m.faces);
    }
}

static void test_nul_byte(void **state)
{
    char path[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/nul.obj", (const char *)*state);
    static const char text[] = TRI "f 1 2 3\n\0f 1 2 3\n";
    tcb_error err = {0};
    assert_int_equal(tcb_write_file_atomic(path, text, sizeof text - 1, &err), TCB_OK);
    tcb_mesh m;
    assert_int_equal(tcb_obj_read(path, &m, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, ":5: NUL byte"));
}

static void test_unreadable_path(void **state)
{
    char path[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/missing.obj", (const char *)*state);
    tcb_mesh m;
    tcb_error err = {0};
    assert_int_equal(tcb_obj_read(path, &m, &err), TCB_ERR_IO);
    assert_non_null(strstr(err.msg, path));
    /* A directory is not a readable mesh either. */
    assert_int_equal(tcb_obj_read(*state, &m, &err), TCB_ERR_IO);
}

static void test_write_round_trip(void **state)
{
    const float v[4 * 3] = {0.1f, -3.4e38f, 1e-7f, 1.0f / 3.0f, 2.0f, 123456.789f, 0, 0, 0, -0.0f, 7, 8};
    const int32_t f[2 * 3] = {0, 1, 2, 3, 2, 1};
    char path[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/sub/out.obj", (const char *)*state);
    tcb_error err = {0};
    assert_int_equal(tcb_obj_write(path, v, 4, f, 2, &err), TCB_OK);
    tcb_mesh m;
    assert_int_equal(tcb_obj_read(path, &m, &err), TCB_OK);
    assert_int_equal(m.n_verts, 4);
    assert_memory_equal(m.verts, v, sizeof v); /* %.9g round-trips floats */
    assert_faces(&m, f, 2);
    tcb_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_index_forms, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_polygons_fan, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_tolerated_syntax, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_face_before_vertices, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_bad_inputs, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_nul_byte, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_unreadable_path, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_write_round_trip, tu_setup_tmpdir, tu_teardown_tmpdir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

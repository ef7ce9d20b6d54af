/* The registry and the sanity methods oracle and nearest, through their
 * method tables exactly as the harness calls them. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <string.h>

#include "tcb/registry.h"
#include "tcb/sequence.h"

/* Two frames of three vertices; frame 1 is frame 0 shifted and permuted in space. */
static void make_sequence(tcb_sequence *s)
{
    tcb_error err;
    assert_int_equal(tcb_sequence_alloc(s, "tiny", 2, 3, 1, &err), TCB_OK);
    const float v[2][9] = {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {5, 5, 5, 6, 5, 5, 5, 6, 5}};
    memcpy(s->verts, v, sizeof v);
    const int32_t f[3] = {0, 1, 2};
    memcpy(s->faces, f, sizeof f);
}

static void test_registry_lists_builtins(void **state)
{
    (void)state;
    assert_true(tcb_registry_count() >= 2);
    assert_non_null(tcb_registry_find("oracle"));
    assert_non_null(tcb_registry_find("nearest"));
    assert_null(tcb_registry_find("no-such-method"));
    for (int k = 0; k < tcb_registry_count(); k++) {
        const tcb_method_ops *ops = tcb_registry_get(k);
        assert_int_equal(ops->abi_version, TCB_METHOD_ABI_VERSION);
        assert_ptr_equal(tcb_registry_find(ops->name), ops);
        assert_string_equal(tcb_registry_origin(k), "built-in");
    }
    assert_null(tcb_registry_get(tcb_registry_count()));
}

static void test_registry_rejects_missing_plugin(void **state)
{
    (void)state;
    tcb_error err;
    assert_int_equal(tcb_registry_load_plugin("/nonexistent/libnothing.so", &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "/nonexistent/libnothing.so"));
}

static void test_oracle_is_exact(void **state)
{
    (void)state;
    tcb_sequence s;
    make_sequence(&s);
    const tcb_method_ops *ops = tcb_registry_find("oracle");
    tcb_error err;
    void *self;
    assert_int_equal(ops->create("{}", &self, &err), TCB_OK);
    tcb_fit_ctx ctx = {0};
    assert_int_equal(ops->fit(self, &s, &ctx, &err), TCB_OK);
    float out[9];
    tcb_rng rng;
    tcb_rng_seed(&rng, 1);
    assert_int_equal(ops->transfer(self, &s, 0, 1, tcb_seq_frame(&s, 0), 3, out, &rng, &err), TCB_OK);
    assert_memory_equal(out, tcb_seq_frame(&s, 1), sizeof out);
    /* The oracle only knows how to move whole frames of GT vertices. */
    assert_int_equal(ops->transfer(self, &s, 0, 1, tcb_seq_frame(&s, 0), 2, out, &rng, &err), TCB_ERR_INPUT);
    ops->destroy(self);
    tcb_sequence_free(&s);
}

static void test_nearest_passes_points_through(void **state)
{
    (void)state;
    tcb_sequence s;
    make_sequence(&s);
    const tcb_method_ops *ops = tcb_registry_find("nearest");
    tcb_error err;
    void *self;
    assert_int_equal(ops->create(NULL, &self, &err), TCB_OK);
    float out[9];
    tcb_rng rng;
    tcb_rng_seed(&rng, 1);
    assert_int_equal(ops->transfer(self, &s, 1, 0, tcb_seq_frame(&s, 1), 3, out, &rng, &err), TCB_OK);
    assert_memory_equal(out, tcb_seq_frame(&s, 1), sizeof out);
    assert_null(ops->reconstruct);
    ops->destroy(self);
    tcb_sequence_free(&s);
}

static void test_params_are_validated(void **state)
{
    (void)state;
    const char *names[] = {"oracle", "nearest"};
    for (int k = 0; k < 2; k++) {
        const tcb_method_ops *ops = tcb_registry_find(names[k]);
        tcb_error err;
        void *self = NULL;
        assert_int_equal(ops->create("{\"k\": 3}", &self, &err), TCB_ERR_INPUT);
        assert_non_null(strstr(err.msg, names[k]));
        assert_non_null(strstr(err.msg, ".k"));
        assert_int_equal(ops->create("[1, 2", &self, &err), TCB_ERR_INPUT);
        assert_non_null(strstr(err.msg, "invalid JSON"));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_registry_lists_builtins),
        cmocka_unit_test(test_registry_rejects_missing_plugin),
        cmocka_unit_test(test_oracle_is_exact),
        cmocka_unit_test(test_nearest_passes_points_through),
        cmocka_unit_test(test_params_are_validated),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

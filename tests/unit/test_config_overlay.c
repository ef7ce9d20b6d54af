/* What the command line changes in a config (config/config_overlay.c): the
 * variant (seeds, params merged by label or method name, the output
 * directory), the dataset roots from --root and the environment, and the
 * per-method "datasets" and the "reference" keys. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"
#include "tcb/config.h"

static const char paper_like[] =
    "{ \"name\": \"tab\", \"seeds\": [7],\n"
    "  \"reference\": {\"source\": \"iccv21\", \"tables\": [\"5\", \"7\"]},\n"
    "  \"variants\": {\n"
    "    \"cpu\": {\"seeds\": [0]},\n"
    "    \"paper\": {\"seeds\": [0, 1], \"params\": {\"mca\": {\"preset\": \"paper\"},\n"
    "                                              \"near\": {\"k\": 2}}}},\n"
    "  \"datasets\": [\n"
    "    {\"name\": \"ama\", \"source\": \"objdir\", \"optional\": true,\n"
    "     \"sequences\": [{\"name\": \"crane\", \"role\": \"validation\"}]},\n"
    "    {\"name\": \"my-set\", \"source\": \"objdir\", \"root\": \"in/config\",\n"
    "     \"sequences\": [{\"name\": \"cat\", \"role\": \"test\"}]}],\n"
    "  \"methods\": [{\"name\": \"near\", \"method\": \"nearest\"},\n"
    "              {\"name\": \"a\", \"method\": \"mca\", \"params\": {\"delta\": 2, \"preset\": \"cpu\"}},\n"
    "              {\"name\": \"b\", \"method\": \"mca\", \"datasets\": [\"ama\"]}] }";

static void test_first_variant_is_the_default(void **state)
{
    (void)state;
    tcb_config c;
    tcb_error err = {0};
    assert_int_equal(tcb_config_parse(paper_like, "t.json", &c, &err), TCB_OK);
    assert_string_equal(c.output, "runs/tab/cpu");
    assert_int_equal(c.n_seeds, 1);
    assert_int_equal(c.seeds[0], 0);
    assert_string_equal(c.methods[1].params_json, "{\"delta\":2,\"preset\":\"cpu\"}");
    assert_string_equal(c.reference, "iccv21");
    assert_int_equal(c.n_reference_tables, 2);
    assert_string_equal(c.reference_tables[1], "7");
    assert_null(strstr(c.json_text, "variants")); /* the saved config is the resolved one */
    assert_non_null(strstr(c.json_text, "\"tables\""));
    tcb_config_free(&c);
}

static void test_variant_merges_params_preset_first(void **state)
{
    (void)state;
    tcb_config_opts o = {.variant = "paper"};
    tcb_config c;
    tcb_error err = {0};
    assert_int_equal(tcb_config_parse_opts(paper_like, "t.json", &o, &c, &err), TCB_OK);
    assert_string_equal(c.output, "runs/tab/paper");
    assert_int_equal(c.n_seeds, 2);
    assert_string_equal(c.methods[0].params_json, "{\"k\":2}");                      /* by label */
    assert_string_equal(c.methods[1].params_json, "{\"preset\":\"paper\",\"delta\":2}"); /* by method name */
    assert_string_equal(c.methods[2].params_json, "{\"preset\":\"paper\"}");
    tcb_config_free(&c);
}

static void test_variant_errors(void **state)
{
    (void)state;
    static const struct {
        const char *variant;
        const char *text;
        const char *expect;
    } cases[] = {
        {"gpu", paper_like, "t.json: --variant gpu: unknown (the config has cpu, paper)"},
        {"cpu", "{\"name\": \"x\", \"datasets\": [], \"methods\": []}", "t.json: --variant cpu: the config has no variants"},
        {NULL, "{\"name\": \"x\", \"variants\": {\"v\": {\"params\": {\"zz\": {}}}}, \"methods\": [{\"name\": \"m\"}]}",
         "t.json: variants.v.params.zz: no method has that name or label"},
        {NULL, "{\"name\": \"x\", \"variants\": {\"v\": {\"iterations\": 3}}}", "t.json: variants.v.iterations: unknown key"},
        {NULL, "{\"name\": \"x\", \"variants\": {}}", "t.json: variants: expected an object naming at least one variant"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        tcb_config_opts o = {.variant = cases[k].variant};
        tcb_config c;
        tcb_error err = {0};
        int rc = tcb_config_parse_opts(cases[k].text, "t.json", &o, &c, &err);
        if (rc != TCB_ERR_INPUT || !strstr(err.msg, cases[k].expect))
            fail_msg("case %zu: rc %d, message \"%s\", expected \"%s\"", k, rc, err.msg, cases[k].expect);
    }
}

static void test_roots_from_flag_env_and_config(void **state)
{
    (void)state;
    tcb_root_override roots[] = {{"ama", "/data/ama"}};
    tcb_config_opts o = {NULL, 1, roots};
    setenv("TCBENCH_ROOT_MY_SET", "/env/my-set", 1);
    tcb_config c;
    tcb_error err = {0};
    assert_int_equal(tcb_config_parse_opts(paper_like, "t.json", &o, &c, &err), TCB_OK);
    assert_string_equal(c.datasets[0].root, "/data/ama");
    assert_string_equal(c.datasets[1].root, "/env/my-set"); /* the environment beats the config */
    tcb_config_free(&c);
    unsetenv("TCBENCH_ROOT_MY_SET");
    assert_int_equal(tcb_config_parse(paper_like, "t.json", &c, &err), TCB_OK);
    assert_string_equal(c.datasets[0].root, ""); /* left to the runner: "no root given" */
    assert_string_equal(c.datasets[1].root, "in/config");
    tcb_config_free(&c);

    tcb_root_override typo[] = {{"amma", "/data/ama"}};
    o = (tcb_config_opts){NULL, 1, typo};
    assert_int_equal(tcb_config_parse_opts(paper_like, "t.json", &o, &c, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "t.json: --root amma=...: the config has no dataset 'amma'"));

    char var[64];
    tcb_config_root_env_name("dfaust-2", var, sizeof var);
    assert_string_equal(var, "TCBENCH_ROOT_DFAUST_2");
}

static void test_method_datasets(void **state)
{
    (void)state;
    tcb_config c;
    tcb_error err = {0};
    assert_int_equal(tcb_config_parse(paper_like, "t.json", &c, &err), TCB_OK);
    assert_true(tcb_method_runs_on(&c.methods[0], "my-set"));
    assert_true(tcb_method_runs_on(&c.methods[2], "ama"));
    assert_false(tcb_method_runs_on(&c.methods[2], "my-set"));
    assert_non_null(strstr(c.json_text, "\"datasets\":\t[\"ama\"]"));
    tcb_config_free(&c);
    static const char *const bad[][2] = {
        {"[\"nope\"]", "t.json: methods[0].datasets[0]: expected the name of one of the config's datasets"},
        {"[\"synth\", \"synth\"]", "t.json: methods[0].datasets[1]: duplicate dataset 'synth'"},
        {"[]", "t.json: methods[0].datasets: must list at least one dataset"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "{\"name\": \"t\", \"datasets\": [{\"name\": \"synth\", \"source\": \"synthetic\", \"sequences\": "
                 "[{\"name\": \"quadruped_walk\", \"role\": \"test\"}]}], \"methods\": [{\"name\": \"nearest\", "
                 "\"datasets\": %s}]}",
                 bad[k][0]);
        int rc = tcb_config_parse(text, "t.json", &c, &err);
        if (rc != TCB_ERR_INPUT || !strstr(err.msg, bad[k][1]))
            fail_msg("case %zu: rc %d, message \"%s\", expected \"%s\"", k, rc, err.msg, bad[k][1]);
    }
}

static void test_reference_errors(void **state)
{
    (void)state;
    static const char *const bad[][2] = {
        {"{\"source\": \"iccv21\"}", "t.json: reference.tables: required key is missing"},
        {"{\"source\": \"iccv21\", \"tables\": []}", "t.json: reference.tables: must list 1 to 16 tables"},
        {"{\"source\": \"iccv21\", \"tables\": [5]}", "t.json: reference.tables[0]: expected a table id"},
        {"{\"tables\": [\"5\"]}", "t.json: reference.source: required key is missing"},
        {"{\"source\": \"a\", \"tables\": [\"5\"], \"x\": 1}", "t.json: reference.x: unknown key"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "{\"name\": \"t\", \"reference\": %s, \"datasets\": [{\"name\": \"synth\", \"source\": "
                 "\"synthetic\", \"sequences\": [{\"name\": \"quadruped_walk\", \"role\": \"test\"}]}], "
                 "\"methods\": [{\"name\": \"nearest\"}]}",
                 bad[k][0]);
        tcb_config c;
        tcb_error err = {0};
        int rc = tcb_config_parse(text, "t.json", &c, &err);
        if (rc != TCB_ERR_INPUT || !strstr(err.msg, bad[k][1]))
            fail_msg("case %zu: rc %d, message \"%s\", expected \"%s\"", k, rc, err.msg, bad[k][1]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_first_variant_is_the_default),
        cmocka_unit_test(test_variant_merges_params_preset_first),
        cmocka_unit_test(test_variant_errors),
        cmocka_unit_test(test_roots_from_flag_env_and_config),
        cmocka_unit_test(test_method_datasets),
        cmocka_unit_test(test_reference_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/* The run configuration: defaults, the normalized JSON, and one error per
 * kind of mistake, each naming the key path. */
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

#define DEFAULT_DATASET                                                                        \
    "{\"name\": \"synth\", \"source\": \"synthetic\", "                                       \
    "\"sequences\": [{\"name\": \"quadruped_walk\", \"role\": \"test\"}]}"
#define DEFAULT_METHOD "{\"name\": \"nearest\"}"

/* {"name": "t", <top>, "datasets": [<datasets>], "methods": [<methods>]};
 * NULL pieces take a valid default. */
static char *config_text(const char *top, const char *datasets, const char *methods)
{
    static char buf[8192];
    snprintf(buf, sizeof buf, "{\"name\": \"t\", %s%s\"datasets\": [%s], \"methods\": [%s]}",
             top ? top : "", top ? ", " : "", datasets ? datasets : DEFAULT_DATASET,
             methods ? methods : DEFAULT_METHOD);
    return buf;
}

static void test_full_config(void **state)
{
    (void)state;
    const char *text =
        "{ \"name\": \"full\", \"output\": \"out/full\", \"splits_dir\": \"sp\",\n"
        "  \"cache_dir\": \"\", \"plugins\": [\"a.so\", \"b.so\"], \"seeds\": [3, 1],\n"
        "  \"threads\": 8,\n"
        "  \"evaluation\": {\"pairs\": 20, \"split_seed\": 7, \"pool_size\": 300,\n"
        "                  \"pool_seed\": 9, \"input_points\": 100},\n"
        "  \"datasets\": [\n"
        "    {\"name\": \"synth\", \"source\": \"synthetic\", \"seed\": 5, \"frames\": 12,\n"
        "     \"normalization\": \"none\", \"sampling\": \"with_replacement\",\n"
        "     \"sequences\": [{\"name\": \"quadruped_walk\", \"role\": \"validation\"}]},\n"
        "    {\"name\": \"anim\", \"source\": \"objdir\", \"root\": \"data/anim\",\n"
        "     \"optional\": true, \"normalization\": \"per_frame\",\n"
        "     \"sequences\": [{\"name\": \"cat_walk\", \"role\": \"train\"},\n"
        "                     {\"name\": \"horse\", \"role\": \"test\"}]}],\n"
        "  \"methods\": [{\"name\": \"oracle\"},\n"
        "              {\"name\": \"near2\", \"method\": \"nearest\", \"params\": {\"k\": 2},\n"
        "               \"seeds\": [5]}] }";
    tcb_config c;
    tcb_error err = {0};
    assert_int_equal(tcb_config_parse(text, "full.json", &c, &err), TCB_OK);
    assert_string_equal(c.path, "full.json");
    assert_string_equal(c.name, "full");
    assert_string_equal(c.output, "out/full");
    assert_string_equal(c.splits_dir, "sp");
    assert_string_equal(c.cache_dir, "");
    assert_int_equal(c.n_plugins, 2);
    assert_string_equal(c.plugins[1], "b.so");
    assert_int_equal(c.n_seeds, 2);
    assert_int_equal(c.seeds[0], 3);
    assert_int_equal(c.seeds[1], 1);
    assert_int_equal(c.threads, 8);
    assert_int_equal(c.eval_pairs, 20);
    assert_int_equal(c.split_seed, 7);
    assert_int_equal(c.pool_size, 300);
    assert_int_equal(c.pool_seed, 9);
    assert_int_equal(c.input_points, 100);
    assert_int_equal(c.n_datasets, 2);
    const tcb_dataset_spec *s = &c.datasets[0], *a = &c.datasets[1];
    assert_int_equal(s->source, TCB_SOURCE_SYNTHETIC);
    assert_int_equal(s->seed, 5);
    assert_int_equal(s->frames, 12);
    assert_int_equal(s->norm, TCB_NORM_NONE);
    assert_int_equal(s->with_replacement, 1);
    assert_int_equal(s->sequences[0].role, TCB_ROLE_VALIDATION);
    assert_int_equal(a->source, TCB_SOURCE_OBJDIR);
    assert_string_equal(a->root, "data/anim");
    assert_int_equal(a->optional, 1);
    assert_int_equal(a->norm, TCB_NORM_PER_FRAME);
    assert_int_equal(a->with_replacement, 0);
    assert_int_equal(a->n_sequences, 2);
    assert_string_equal(a->sequences[1].name, "horse");
    assert_int_equal(a->sequences[0].role, TCB_ROLE_TRAIN);
    assert_int_equal(c.n_methods, 2);
    assert_string_equal(c.methods[0].label, "oracle");
    assert_string_equal(c.methods[0].method, "oracle");
    assert_string_equal(c.methods[0].params_json, "{}");
    assert_string_equal(c.methods[1].label, "near2");
    assert_string_equal(c.methods[1].method, "nearest");
    assert_string_equal(c.methods[1].params_json, "{\"k\":2}");
    /* A method without its own seeds runs the config's. */
    assert_int_equal(c.methods[0].n_seeds, 2);
    assert_int_equal(c.methods[0].seeds[0], 3);
    assert_int_equal(c.methods[0].seeds[1], 1);
    assert_int_equal(c.methods[1].n_seeds, 1);
    assert_int_equal(c.methods[1].seeds[0], 5);
    tcb_config_free(&c);
}

static void test_defaults(void **state)
{
    (void)state;
    tcb_config c;
    tcb_error err = {0};
    assert_int_equal(tcb_config_parse(config_text(NULL, NULL, NULL), "t.json", &c, &err), TCB_OK);
    assert_string_equal(c.output, "runs/t");
    assert_string_equal(c.splits_dir, "splits");
    assert_string_equal(c.cache_dir, ".tcbench-cache");
    assert_int_equal(c.n_plugins, 0);
    assert_int_equal(c.n_seeds, 1);
    assert_int_equal(c.seeds[0], 0);
    assert_int_equal(c.threads, 2);
    assert_int_equal(c.eval_pairs, 500);
    assert_int_equal(c.split_seed, 2021);
    assert_int_equal(c.pool_size, 10000);
    assert_int_equal(c.pool_seed, 0);
    assert_int_equal(c.input_points, 2500);
    assert_int_equal(c.protocols, TCB_PROTOCOL_PAIRS);
    assert_int_equal(c.eval_clips, TCB_DEFAULT_EVAL_CLIPS);
    assert_null(strstr(c.json_text, "protocol")); /* the default is not spelled out: older run records */
    assert_int_equal(c.datasets[0].seed, 0);
    assert_int_equal(c.datasets[0].frames, 0);
    assert_int_equal(c.datasets[0].norm, TCB_NORM_FIRST_FRAME);
    assert_int_equal(c.datasets[0].with_replacement, 0);
    assert_int_equal(c.datasets[0].optional, 0);
    assert_string_equal(c.methods[0].method, "nearest");
    assert_string_equal(c.methods[0].params_json, "{}");
    tcb_config_free(&c);
}

/* json_text spells out every default and parses back to itself. */
static void test_normalized_json(void **state)
{
    (void)state;
    tcb_config c, again;
    tcb_error err = {0};
    const char *text = config_text("\"seeds\": [4]", NULL,
                                   "{\"name\": \"n\", \"method\": \"nearest\", \"params\": {\"x\": [1, 2]}}, "
                                   "{\"name\": \"o\", \"method\": \"oracle\", \"seeds\": [2, 4]}");
    assert_int_equal(tcb_config_parse(text, "t.json", &c, &err), TCB_OK);
    assert_non_null(strstr(c.json_text, "\"pairs\":\t500"));
    assert_non_null(strstr(c.json_text, "\"cache_dir\":\t\".tcbench-cache\""));
    assert_non_null(strstr(c.json_text, "\"normalization\":\t\"first_frame\""));
    assert_non_null(strstr(c.json_text, "\"method\":\t\"nearest\""));
    assert_int_equal(tcb_config_parse(c.json_text, "normalized", &again, &err), TCB_OK);
    assert_string_equal(again.json_text, c.json_text);
    assert_string_equal(again.methods[0].params_json, "{\"x\":[1,2]}");
    /* Only a method's own seeds are spelled out. */
    assert_int_equal(again.methods[0].n_seeds, 1);
    assert_int_equal(again.methods[1].n_seeds, 2);
    assert_int_equal(again.methods[1].seeds[1], 4);
    const char *n = strstr(c.json_text, "\"name\":\t\"n\""), *o = strstr(n, "\"name\":\t\"o\"");
    assert_true(strstr(n, "\"seeds\"") > o);
    tcb_config_free(&again);
    tcb_config_free(&c);
}

/* "protocol": one name or a list; the normalized JSON spells out a
 * non-default one, with its clip count, and parses back to itself. */
static void test_protocols(void **state)
{
    (void)state;
    static const struct {
        const char *eval, *json;
        int bits;
    } cases[] = {
        {"\"evaluation\": {\"protocol\": \"pairs\"}", NULL, TCB_PROTOCOL_PAIRS},
        {"\"evaluation\": {\"protocol\": [\"pairs\"]}", NULL, TCB_PROTOCOL_PAIRS},
        {"\"evaluation\": {\"protocol\": \"clips\", \"clips\": 4}", "\"protocol\":\t\"clips\",\n\t\t\"clips\":\t4",
         TCB_PROTOCOL_CLIPS},
        {"\"evaluation\": {\"protocol\": [\"clips\", \"pairs\"]}", "\"clips\":\t10", TCB_PROTOCOL_PAIRS | TCB_PROTOCOL_CLIPS},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        tcb_config c, again;
        tcb_error err = {0};
        assert_int_equal(tcb_config_parse(config_text(cases[k].eval, NULL, NULL), "t.json", &c, &err), TCB_OK);
        assert_int_equal(c.protocols, cases[k].bits);
        if (cases[k].json && !strstr(c.json_text, cases[k].json)) fail_msg("no %s in %s", cases[k].json, c.json_text);
        if (!cases[k].json) assert_null(strstr(c.json_text, "protocol"));
        assert_int_equal(tcb_config_parse(c.json_text, "normalized", &again, &err), TCB_OK);
        assert_string_equal(again.json_text, c.json_text);
        tcb_config_free(&again);
        tcb_config_free(&c);
    }
}

static void test_load_file(void **state)
{
    (void)state;
    char dir[512], path[1024];
    tu_make_tmpdir(dir, sizeof dir);
    tu_write_text(dir, "c.json", config_text(NULL, NULL, NULL), path, sizeof path);
    tcb_config c;
    tcb_error err = {0};
    assert_int_equal(tcb_config_load(path, &c, &err), TCB_OK);
    assert_string_equal(c.path, path);
    tcb_config_free(&c);
    strcat(path, ".missing");
    assert_int_equal(tcb_config_load(path, &c, &err), TCB_ERR_IO);
    assert_non_null(strstr(err.msg, ".missing"));
    tu_remove_tree(dir);
}

typedef struct bad_case {
    const char *top, *datasets, *methods;
    const char *expect; /* substring of the message */
} bad_case;

#define SEQ(name, role) "{\"name\": \"" name "\", \"role\": \"" role "\"}"
#define SYNTH(extra, seqs) \
    "{\"name\": \"synth\", \"source\": \"synthetic\", " extra "\"sequences\": [" seqs "]}"
#define OBJDIR(extra) \
    "{\"name\": \"a\", \"source\": \"objdir\", \"root\": \"r\", " extra "\"sequences\": [" SEQ("cat", "test") "]}"
#define DFAUST(extra, seqs) \
    "{\"name\": \"dfaust\", \"source\": \"dfaust\", " extra "\"sequences\": [" seqs "]}"
#define DFAUST_SUBJECTS(list) DFAUST("\"root\": \"d\", \"subjects\": " list ", ", SEQ("hips", "test"))

static const bad_case bad_cases[] = {
    /* types */
    {"\"threads\": \"two\"", NULL, NULL, "t.json: threads: expected an integer, got a string"},
    {"\"threads\": 0", NULL, NULL, "t.json: threads: 0 is out of range"},
    {"\"seeds\": 3", NULL, NULL, "t.json: seeds: expected an array"},
    {"\"seeds\": [1, -2]", NULL, NULL, "t.json: seeds[1]: expected a non-negative integer"},
    {"\"seeds\": [1, 1]", NULL, NULL, "t.json: seeds[1]: duplicate seed 1"},
    {"\"seeds\": []", NULL, NULL, "t.json: seeds: must list at least one seed"},
    {"\"plugins\": [\"\"]", NULL, NULL, "t.json: plugins[0]: expected a non-empty path"},
    {"\"evaluation\": {\"pairs\": 0}", NULL, NULL, "t.json: evaluation.pairs: 0 is out of range"},
    {"\"evaluation\": {\"protocol\": \"clip\"}", NULL, NULL,
     "t.json: evaluation.protocol: expected \"pairs\", \"clips\" or a list of them (each once), got \"clip\""},
    {"\"evaluation\": {\"protocol\": []}", NULL, NULL, "t.json: evaluation.protocol: expected"},
    {"\"evaluation\": {\"protocol\": [\"clips\", \"clips\"]}", NULL, NULL, "t.json: evaluation.protocol: expected"},
    {"\"evaluation\": {\"protocol\": [\"pairs\", 2]}", NULL, NULL, "got [\"pairs\",2]"},
    {"\"evaluation\": {\"protocol\": 1}", NULL, NULL, "t.json: evaluation.protocol: expected"},
    {"\"evaluation\": {\"clips\": 4}", NULL, NULL, "t.json: evaluation.clips: only with the clip protocol"},
    {"\"evaluation\": {\"protocol\": \"clips\", \"clips\": 0}", NULL, NULL, "t.json: evaluation.clips: 0 is out of range"},
    {"\"evaluation\": {\"pairs\": 2.5}", NULL, NULL, "t.json: evaluation.pairs: expected an integer"},
    {"\"evaluation\": []", NULL, NULL, "t.json: evaluation: expected an object"},
    {NULL, SYNTH("\"frames\": true, ", SEQ("quadruped_walk", "test")), NULL,
     "t.json: datasets[0].frames: expected an integer, got a boolean"},
    {NULL, NULL, "{\"name\": \"n\", \"params\": [1]}", "t.json: methods[0].params: expected an object"},
    {NULL, NULL, "{\"name\": \"n\", \"seeds\": 1}", "t.json: methods[0].seeds: expected an array"},
    {NULL, NULL, "{\"name\": \"n\", \"seeds\": []}", "t.json: methods[0].seeds: must list at least one seed"},
    {NULL, NULL, "{\"name\": \"n\", \"seeds\": [0, 0.5]}",
     "t.json: methods[0].seeds[1]: expected a non-negative integer"},
    {NULL, NULL, "{\"name\": \"n\", \"seeds\": [2, 2]}", "t.json: methods[0].seeds[1]: duplicate seed 2"},
    {NULL, NULL, "{\"name\": 3}", "t.json: methods[0].name: expected a string, got a number"},
    {NULL, "3", NULL, "t.json: datasets[0]: expected an object, got a number"},
    /* unknown keys at every level */
    {"\"thread\": 2", NULL, NULL, "t.json: thread: unknown key"},
    {"\"evaluation\": {\"pair\": 2}", NULL, NULL, "t.json: evaluation.pair: unknown key"},
    {NULL, SYNTH("\"roots\": \"x\", ", SEQ("quadruped_walk", "test")), NULL,
     "t.json: datasets[0].roots: unknown key"},
    {NULL, SYNTH("", "{\"name\": \"quadruped_walk\", \"role\": \"test\", \"rol\": 1}"), NULL,
     "t.json: datasets[0].sequences[0].rol: unknown key"},
    {NULL, NULL, "{\"name\": \"nearest\", \"param\": {}}", "t.json: methods[0].param: unknown key"},
    {NULL, SYNTH("\"root\": \"x\", ", SEQ("quadruped_walk", "test")), NULL,
     "t.json: datasets[0].root: unknown key"},
    {NULL, OBJDIR("\"frames\": 3, "), NULL, "t.json: datasets[0].frames: unknown key"},
    /* values */
    {NULL, SYNTH("", SEQ("quadruped_walk", "test") ", " SEQ("quadruped_trot", "tset")), NULL,
     "t.json: datasets[0].sequences[1].role: unknown role 'tset' (expected train, validation or "
     "test)"},
    {NULL, SYNTH("\"normalization\": \"first\", ", SEQ("quadruped_walk", "test")), NULL,
     "t.json: datasets[0].normalization: unknown value 'first'"},
    {NULL, SYNTH("\"sampling\": \"random\", ", SEQ("quadruped_walk", "test")), NULL,
     "t.json: datasets[0].sampling: unknown value 'random'"},
    {NULL, "{\"name\": \"s\", \"source\": \"hdf5\", \"sequences\": []}", NULL,
     "t.json: datasets[0].source: unknown value 'hdf5'"},
    {NULL, SYNTH("", SEQ("no_such_shape", "test")), NULL,
     "t.json: datasets[0].sequences[0].name: unknown synthetic sequence 'no_such_shape'"},
    {NULL, NULL, "{\"name\": \"../up\"}", "t.json: methods[0].name: '../up' must not start with '.'"},
    {NULL, NULL, "{\"name\": \"a/b\"}", "t.json: methods[0].name: 'a/b' may only contain"},
    {NULL, NULL, "{\"params\": {}}", "t.json: methods[0].name: required key is missing"},
    /* duplicates and empty lists */
    {NULL, NULL, DEFAULT_METHOD ", {\"name\": \"oracle\"}, " DEFAULT_METHOD,
     "t.json: methods[2].name: duplicate method label 'nearest' (also methods[0])"},
    {NULL, DEFAULT_DATASET ", " DEFAULT_DATASET, NULL,
     "t.json: datasets[1].name: duplicate dataset 'synth' (also datasets[0])"},
    {NULL, SYNTH("", SEQ("quadruped_walk", "test") ", " SEQ("quadruped_walk", "train")), NULL,
     "t.json: datasets[0].sequences[1].name: duplicate sequence 'quadruped_walk'"},
    {NULL, NULL, "", "t.json: methods: must list at least one method"},
    {NULL, "", NULL, "t.json: datasets: must list at least one dataset"},
    {NULL, SYNTH("", ""), NULL, "t.json: datasets[0].sequences: must list at least one sequence"},
    /* dfaust */
    {NULL, DFAUST_SUBJECTS("\"50002\""), NULL, "t.json: datasets[0].subjects: expected an array"},
    {NULL, DFAUST_SUBJECTS("[]"), NULL, "t.json: datasets[0].subjects: must list at least one subject"},
    {NULL, DFAUST_SUBJECTS("[50002]"), NULL, "datasets[0].subjects[0]: expected a subject id string"},
    {NULL, DFAUST_SUBJECTS("[\"50002\", \"a/b\"]"), NULL, "t.json: datasets[0].subjects[1]: 'a/b' may only"},
    {NULL, DFAUST_SUBJECTS("[\"50002\", \"50002\"]"), NULL, "subjects[1]: duplicate subject '50002'"},
    {NULL, DFAUST("\"root\": \"d\", \"frames\": 3, ", SEQ("hips", "test")), NULL,
     "t.json: datasets[0].frames: unknown key"},
    {NULL, DFAUST("\"root\": \"d\", \"align_rotation\": true, ", SEQ("hips", "test")), NULL,
     "t.json: datasets[0].align_rotation: unknown key"},
    {NULL, OBJDIR("\"subjects\": [\"1\"], "), NULL, "t.json: datasets[0].subjects: unknown key"},
};

static void test_bad_configs(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof bad_cases / sizeof bad_cases[0]; k++) {
        const bad_case *b = &bad_cases[k];
        tcb_config c;
        tcb_error err = {0};
        int rc = tcb_config_parse(config_text(b->top, b->datasets, b->methods), "t.json", &c, &err);
        if (rc != TCB_ERR_INPUT || !strstr(err.msg, b->expect))
            fail_msg("case %zu: rc %d, message \"%s\", expected \"%s\"", k, rc, err.msg, b->expect);
        assert_null(c.json_text); /* freed on error */
    }
}

/* "source": "dfaust": raw coordinates and draws with replacement unless
 * told otherwise (§1.2, §1.3); every subject unless listed, the list in
 * the normalized JSON. */
static void test_dfaust_dataset(void **state)
{
    (void)state;
    tcb_config c, again;
    tcb_error err = {0};
    const char *text =
        config_text(NULL, DFAUST("\"root\": \"data/dfaust\", ", SEQ("jumping_jacks", "validation")), NULL);
    assert_int_equal(tcb_config_parse(text, "t.json", &c, &err), TCB_OK);
    const tcb_dataset_spec *d = &c.datasets[0];
    assert_int_equal(d->source, TCB_SOURCE_DFAUST);
    assert_string_equal(d->root, "data/dfaust");
    assert_int_equal(d->norm, TCB_NORM_NONE);
    assert_int_equal(d->with_replacement, 1);
    assert_int_equal(d->n_subjects, 0);
    assert_non_null(strstr(c.json_text, "\"source\":\t\"dfaust\""));
    assert_non_null(strstr(c.json_text, "\"sampling\":\t\"with_replacement\""));
    assert_null(strstr(c.json_text, "\"subjects\""));
    assert_int_equal(tcb_config_parse(c.json_text, "normalized", &again, &err), TCB_OK);
    assert_string_equal(again.json_text, c.json_text);
    tcb_config_free(&again), tcb_config_free(&c);

    text = config_text(NULL,
                       DFAUST("\"root\": \"d\", \"optional\": true, \"normalization\": \"per_frame\", "
                              "\"sampling\": \"without_replacement\", \"subjects\": [\"50004\", \"50002\"], ",
                              SEQ("hips", "test")),
                       NULL);
    assert_int_equal(tcb_config_parse(text, "t.json", &c, &err), TCB_OK);
    d = &c.datasets[0];
    assert_int_equal(d->norm, TCB_NORM_PER_FRAME);
    assert_int_equal(d->with_replacement, 0);
    assert_int_equal(d->optional, 1);
    assert_int_equal(d->n_subjects, 2);
    assert_string_equal(d->subjects[0], "50004");
    assert_string_equal(d->subjects[1], "50002");
    assert_int_equal(tcb_config_parse(c.json_text, "normalized", &again, &err), TCB_OK);
    assert_string_equal(again.json_text, c.json_text);
    assert_int_equal(again.datasets[0].n_subjects, 2);
    assert_string_equal(again.datasets[0].subjects[1], "50002");
    tcb_config_free(&again), tcb_config_free(&c);
}

static void test_missing_lists_and_name(void **state)
{
    (void)state;
    static const struct {
        const char *text, *expect;
    } cases[] = {
        {"{\"name\": \"t\", \"methods\": [" DEFAULT_METHOD "]}",
         "t.json: datasets: required key is missing"},
        {"{\"name\": \"t\", \"datasets\": [" DEFAULT_DATASET "]}",
         "t.json: methods: required key is missing"},
        {"{\"datasets\": [" DEFAULT_DATASET "], \"methods\": [" DEFAULT_METHOD "]}",
         "t.json: name: required key is missing"},
        {"[1, 2]", "t.json: expected an object, got an array"},
        {"{\n  \"name\": \"t\",\n  oops\n}", "t.json:3:"},
        {"", "t.json:1:"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        tcb_config c;
        tcb_error err = {0};
        int rc = tcb_config_parse(cases[k].text, "t.json", &c, &err);
        if (rc != TCB_ERR_INPUT || !strstr(err.msg, cases[k].expect))
            fail_msg("case %zu: rc %d, message \"%s\", expected \"%s\"", k, rc, err.msg,
                     cases[k].expect);
    }
}

static void load_one(const char *path, void *arg)
{
    (void)arg;
    tcb_config c;
    tcb_error err = {0};
    if (tcb_config_load(path, &c, &err)) fail_msg("%s", err.msg);
    tcb_config_free(&c);
}

/* Every config shipped in configs/ (configs/paper/ too) parses: a typo
 * there would otherwise surface only when somebody runs that (possibly
 * hours-long) config. */
static void test_shipped_configs_parse(void **state)
{
    (void)state;
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/configs", TCB_SOURCE_DIR);
    assert_true(tu_for_each_json(dir, load_one, NULL) >= 10);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_full_config),
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_normalized_json),
        cmocka_unit_test(test_protocols),
        cmocka_unit_test(test_dfaust_dataset),
        cmocka_unit_test(test_load_file),
        cmocka_unit_test(test_bad_configs),
        cmocka_unit_test(test_missing_lists_and_name),
        cmocka_unit_test(test_shipped_configs_parse),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/* Evaluation splits (make, save/load, obtain, blocks) and training-pair samplers. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "testutil.h"
#include "tcb/fsutil.h"
#include "tcb/split.h"

static void make_ok(const char *seq, tcb_role role, int n_frames, int n_pairs, uint64_t seed,
                    tcb_split *s)
{
    tcb_error err = {0};
    if (tcb_split_make("anim", seq, role, n_frames, NULL, 0, n_pairs, seed, s, &err))
        fail_msg("make: %s", err.msg);
}

static void expect_error(int rc, const tcb_error *err, int code, const char *a, const char *b)
{
    assert_int_equal(rc, code);
    if (a && !strstr(err->msg, a)) fail_msg("'%s' does not name '%s'", err->msg, a);
    if (b && !strstr(err->msg, b)) fail_msg("'%s' does not name '%s'", err->msg, b);
}

static void test_make_deterministic_and_valid(void **state)
{
    (void)state;
    static const int frames[] = {2, 3, 35, 175};
    for (size_t f = 0; f < 4; f++) {
        tcb_split a, b, c, d;
        make_ok("cat_walk", TCB_ROLE_TEST, frames[f], 500, 2021, &a);
        make_ok("cat_walk", TCB_ROLE_TEST, frames[f], 500, 2021, &b);
        make_ok("cat_walk", TCB_ROLE_TEST, frames[f], 500, 2022, &c);
        make_ok("horse_gallop", TCB_ROLE_TEST, frames[f], 500, 2021, &d);
        assert_memory_equal(a.pairs, b.pairs, 500 * 2 * sizeof(int32_t));
        if (frames[f] > 2) { /* with 2 frames there are only two possible pairs */
            assert_memory_not_equal(a.pairs, c.pairs, 500 * 2 * sizeof(int32_t));
            assert_memory_not_equal(a.pairs, d.pairs, 500 * 2 * sizeof(int32_t));
        }
        for (int p = 0; p < 500; p++) {
            assert_in_range(a.pairs[2 * p], 0, frames[f] - 1);
            assert_in_range(a.pairs[2 * p + 1], 0, frames[f] - 1);
            assert_int_not_equal(a.pairs[2 * p], a.pairs[2 * p + 1]);
        }
        assert_string_equal(a.dataset, "anim");
        assert_string_equal(a.sequence, "cat_walk");
        assert_int_equal(a.n_frames, frames[f]);
        tcb_split_free(&a), tcb_split_free(&b), tcb_split_free(&c), tcb_split_free(&d);
    }
}

/* i uniform over 5 frames, j uniform over the other 4: all 20 ordered pairs
 * equally likely. Pearson χ² with 19 degrees of freedom has mean 19; 60 is
 * beyond its 99.999th percentile, so a correct sampler passes with this fixed
 * seed and a biased one (say j = i + 1 mod n) fails by thousands. */
static void test_make_uniform(void **state)
{
    (void)state;
    enum { N = 5, P = 20000 };
    tcb_split s;
    make_ok("cat_walk", TCB_ROLE_TEST, N, P, 7, &s);
    int count[N][N] = {{0}};
    for (int p = 0; p < P; p++) count[s.pairs[2 * p]][s.pairs[2 * p + 1]]++;
    double expected = P / (double)(N * (N - 1)), chi2 = 0.0;
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++)
            if (i != j) chi2 += (count[i][j] - expected) * (count[i][j] - expected) / expected;
    if (chi2 > 60.0) fail_msg("chi^2 = %g over 19 degrees of freedom", chi2);
    tcb_split_free(&s);
}

static void test_make_rejects(void **state)
{
    (void)state;
    tcb_split s;
    tcb_error err = {0};
    expect_error(tcb_split_make("anim", "one", TCB_ROLE_TEST, 1, NULL, 0, 10, 0, &s, &err), &err,
                 TCB_ERR_INPUT, "one", "2 frames");
    expect_error(tcb_split_make("anim", "x", TCB_ROLE_TEST, 5, NULL, 0, -1, 0, &s, &err), &err,
                 TCB_ERR_INPUT, "x", "negative");
}

static void test_save_load_roundtrip(void **state)
{
    (void)state;
    char dir[256], path[512], *text;
    tu_make_tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/sub/cat.json", dir);
    tcb_split s, t;
    tcb_error err = {0};
    make_ok("cat_walk", TCB_ROLE_VALIDATION, 35, 500, 9007199254740992ULL, &s);
    assert_int_equal(tcb_split_save(path, &s, &err), TCB_OK);
    assert_int_equal(tcb_split_load(path, &t, &err), TCB_OK);
    assert_string_equal(t.dataset, "anim");
    assert_string_equal(t.sequence, "cat_walk");
    assert_int_equal(t.role, TCB_ROLE_VALIDATION);
    assert_int_equal(t.n_frames, 35);
    assert_true(t.seed == 9007199254740992ULL);
    assert_int_equal(t.n_pairs, 500);
    assert_memory_equal(s.pairs, t.pairs, 500 * 2 * sizeof(int32_t));
    assert_int_equal(tcb_read_file(path, &text, NULL, &err), TCB_OK);
    assert_non_null(strstr(text, "\"tcbench-split/1\""));
    free(text);

    s.seed = 9007199254740993ULL; /* not representable in a JSON number */
    expect_error(tcb_split_save(path, &s, &err), &err, TCB_ERR_INPUT, path, "seed");
    tcb_split_free(&s), tcb_split_free(&t);
    tu_remove_tree(dir);
}

static void file_identity(const char *path, struct stat *st, char **text)
{
    assert_int_equal(stat(path, st), 0);
    assert_int_equal(tcb_read_file(path, text, NULL, NULL), TCB_OK);
}

static void test_obtain_reuses(void **state)
{
    (void)state;
    char dir[256], path[512], *before, *after;
    tu_make_tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/splits/anim/cat_walk.json", dir);
    tcb_split a, b;
    tcb_error err = {0};
    assert_int_equal(
        tcb_split_obtain(path, "anim", "cat_walk", TCB_ROLE_TEST, 35, NULL, 0, 100, 3, &a, &err), TCB_OK);
    struct stat st1, st2;
    file_identity(path, &st1, &before);
    assert_int_equal(
        tcb_split_obtain(path, "anim", "cat_walk", TCB_ROLE_TEST, 35, NULL, 0, 100, 3, &b, &err), TCB_OK);
    file_identity(path, &st2, &after);
    assert_true(st1.st_ino == st2.st_ino); /* an atomic rewrite would be a new inode */
    assert_true(st1.st_mtim.tv_sec == st2.st_mtim.tv_sec &&
                st1.st_mtim.tv_nsec == st2.st_mtim.tv_nsec);
    assert_string_equal(before, after);
    assert_memory_equal(a.pairs, b.pairs, 100 * 2 * sizeof(int32_t));
    tcb_split_free(&a), tcb_split_free(&b);
    free(before), free(after);

    /* The file is the authority: its pairs are used, not redrawn ones. */
    tu_write_text(dir, "edited.json",
                  "{\"format\": \"tcbench-split/1\", \"dataset\": \"anim\", \"sequence\": \"cat\","
                  " \"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 2,"
                  " \"pairs\": [[3, 0], [3, 0]]}",
                  path, sizeof path);
    assert_int_equal(tcb_split_obtain(path, "anim", "cat", TCB_ROLE_TEST, 4, NULL, 0, 2, 1, &a, &err),
                     TCB_OK);
    assert_true(a.pairs[0] == 3 && a.pairs[1] == 0 && a.pairs[2] == 3 && a.pairs[3] == 0);
    tcb_split_free(&a);
    tu_remove_tree(dir);
}

static void test_obtain_disagreement(void **state)
{
    (void)state;
    char dir[256], path[512];
    tu_make_tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/cat.json", dir);
    tcb_split s;
    tcb_error err = {0};
    assert_int_equal(tcb_split_obtain(path, "anim", "cat", TCB_ROLE_TEST, 35, NULL, 0, 50, 3, &s, &err),
                     TCB_OK);
    tcb_split_free(&s);
    expect_error(tcb_split_obtain(path, "anim", "cat", TCB_ROLE_VALIDATION, 35, NULL, 0, 50, 3, &s, &err),
                 &err, TCB_ERR_INPUT, path, "role");
    assert_null(s.pairs);
    expect_error(tcb_split_obtain(path, "anim", "cat", TCB_ROLE_TEST, 36, NULL, 0, 50, 3, &s, &err), &err,
                 TCB_ERR_INPUT, path, "n_frames");
    expect_error(tcb_split_obtain(path, "anim", "dog", TCB_ROLE_TEST, 35, NULL, 0, 50, 3, &s, &err), &err,
                 TCB_ERR_INPUT, path, "sequence");
    expect_error(tcb_split_obtain(path, "ama", "cat", TCB_ROLE_TEST, 35, NULL, 0, 50, 3, &s, &err), &err,
                 TCB_ERR_INPUT, path, "dataset");
    expect_error(tcb_split_obtain(path, "anim", "cat", TCB_ROLE_TEST, 35, NULL, 0, 500, 3, &s, &err), &err,
                 TCB_ERR_INPUT, path, "n_pairs");
    expect_error(tcb_split_obtain(path, "anim", "cat", TCB_ROLE_TEST, 35, NULL, 0, 50, 4, &s, &err), &err,
                 TCB_ERR_INPUT, path, "seed");
    tu_remove_tree(dir);
}

/* Each malformed file fails with TCB_ERR_INPUT naming the file and the key. */
static void test_load_malformed(void **state)
{
    (void)state;
#define HEAD "\"format\": \"tcbench-split/1\", \"dataset\": \"anim\", \"sequence\": \"cat\", "
    static const struct {
        const char *json, *key;
    } cases[] = {
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, "
         "\"pairs\": [[0, 1]]", ":1:"}, /* truncated: invalid JSON */
        {"[1, 2]", "object"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": \"4\", \"seed\": 1, \"n_pairs\": 1, "
         "\"pairs\": [[0, 1]]}", ".n_frames"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"n_pairs\": 1, \"pairs\": [[0, 1]]}",
         ".seed"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1.5, \"n_pairs\": 1, "
         "\"pairs\": [[0, 1]]}", ".seed"},
        {"{" HEAD "\"role\": \"dev\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, "
         "\"pairs\": [[0, 1]]}", ".role"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, "
         "\"pairs\": [[0, 1]], \"extra\": 0}", ".extra"},
        {"{\"format\": \"tcbench-split/2\", \"dataset\": \"anim\", \"sequence\": \"cat\", "
         "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, \"pairs\": [[0, 1]]}",
         ".format"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 2, "
         "\"pairs\": [[0, 1]]}", ".pairs"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 2, "
         "\"pairs\": [[0, 1], [2, 2]]}", "pairs[1]"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 2, "
         "\"pairs\": [[0, 1], [2, 4]]}", "pairs[1][1]"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, "
         "\"pairs\": [[-1, 1]]}", "pairs[0][0]"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, "
         "\"pairs\": [[0.5, 1]]}", "pairs[0][0]"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, "
         "\"pairs\": [\"0,1\"]}", "pairs[0]"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, "
         "\"pairs\": [[0, 1, 2]]}", "pairs[0]"},
        {"{" HEAD "\"role\": \"test\", \"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, "
         "\"pairs\": {\"0\": 1}}", ".pairs"},
    };
#undef HEAD
    char dir[256], path[512];
    tu_make_tmpdir(dir, sizeof dir);
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        tu_write_text(dir, "bad.json", cases[c].json, path, sizeof path);
        tcb_split s;
        tcb_error err = {0};
        expect_error(tcb_split_load(path, &s, &err), &err, TCB_ERR_INPUT, path, cases[c].key);
        assert_null(s.pairs);
    }
    tcb_split s;
    tcb_error err = {0};
    snprintf(path, sizeof path, "%s/missing.json", dir);
    expect_error(tcb_split_load(path, &s, &err), &err, TCB_ERR_IO, path, NULL);
    tu_remove_tree(dir);
}

static void test_names(void **state)
{
    (void)state;
    for (int r = TCB_ROLE_TRAIN; r <= TCB_ROLE_TEST; r++) {
        tcb_role back;
        assert_int_equal(tcb_role_parse(tcb_role_name((tcb_role)r), &back), 0);
        assert_int_equal(back, r);
    }
    tcb_role role;
    assert_int_equal(tcb_role_parse("validation", &role), 0);
    assert_int_equal(role, TCB_ROLE_VALIDATION);
    assert_int_equal(tcb_role_parse("val", &role), -1);
    tcb_pair_mode mode;
    assert_int_equal(tcb_pair_mode_parse("neighbors", &mode), 0);
    assert_int_equal(mode, TCB_PAIRS_NEIGHBORS);
    assert_int_equal(tcb_pair_mode_parse("random", &mode), 0);
    assert_int_equal(mode, TCB_PAIRS_RANDOM);
    assert_int_equal(tcb_pair_mode_parse("within_seq", &mode), 0);
    assert_int_equal(mode, TCB_PAIRS_WITHIN_SEQ);
    assert_int_equal(tcb_pair_mode_parse("neighbours", &mode), -1);
}

/* Draws 40 j per frame for every i of the block [lo, hi) (a given allowed
 * j is then missed with probability < e^-39); every j must be allowed and
 * every allowed j seen. */
static void check_sampler(tcb_pair_mode mode, int delta, int n, int lo, int hi, tcb_rng *rng)
{
    for (int i = lo; i < hi; i++) {
        int seen[64] = {0};
        for (int t = 0; t < 40 * n; t++) {
            int j = tcb_pair_sample(mode, delta, n, lo, hi, i, rng);
            assert_in_range(j, 0, n - 1);
            seen[j] = 1;
        }
        for (int j = 0; j < n; j++) {
            int in_block = mode == TCB_PAIRS_RANDOM || (j >= lo && j < hi);
            int allowed = j != i && in_block && (mode != TCB_PAIRS_NEIGHBORS || abs(i - j) <= delta);
            if (seen[j] != allowed)
                fail_msg("mode %d, delta %d, %d frames, block [%d, %d), i = %d: j = %d seen %d", (int)mode,
                         delta, n, lo, hi, i, j, seen[j]);
        }
    }
}

static void test_pair_samplers(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 11);
    static const int ns[] = {2, 3, 10, 48};
    static const int deltas[] = {1, 2, 5, 100};
    for (size_t a = 0; a < 4; a++) {
        for (size_t b = 0; b < 4; b++) check_sampler(TCB_PAIRS_NEIGHBORS, deltas[b], ns[a], 0, ns[a], &rng);
        check_sampler(TCB_PAIRS_RANDOM, 0, ns[a], 0, ns[a], &rng);
        check_sampler(TCB_PAIRS_WITHIN_SEQ, 0, ns[a], 0, ns[a], &rng);
    }
    /* blocks: the windows and within_seq stay inside, random crosses */
    static const int blocks[][2] = {{0, 2}, {2, 9}, {9, 12}, {3, 48}};
    for (size_t k = 0; k < 4; k++) {
        int n = k < 3 ? 12 : 48, lo = blocks[k][0], hi = blocks[k][1];
        for (size_t b = 0; b < 4; b++) check_sampler(TCB_PAIRS_NEIGHBORS, deltas[b], n, lo, hi, &rng);
        check_sampler(TCB_PAIRS_RANDOM, 0, n, lo, hi, &rng);
        check_sampler(TCB_PAIRS_WITHIN_SEQ, 0, n, lo, hi, &rng);
    }
    assert_int_equal(tcb_pair_sample(TCB_PAIRS_RANDOM, 1, 1, 0, 1, 0, &rng), -1);
    assert_int_equal(tcb_pair_sample(TCB_PAIRS_NEIGHBORS, 1, 0, 0, 0, 0, &rng), -1);
    assert_int_equal(tcb_pair_sample(TCB_PAIRS_NEIGHBORS, 0, 10, 0, 10, 3, &rng), -1);
    assert_int_equal(tcb_pair_sample(TCB_PAIRS_WITHIN_SEQ, 1, 10, 0, 10, 10, &rng), -1);
    assert_int_equal(tcb_pair_sample(TCB_PAIRS_WITHIN_SEQ, 1, 10, 0, 10, -1, &rng), -1);
    assert_int_equal(tcb_pair_sample(TCB_PAIRS_WITHIN_SEQ, 1, 10, 4, 6, 3, &rng), -1);  /* i outside */
    assert_int_equal(tcb_pair_sample(TCB_PAIRS_RANDOM, 1, 10, 4, 5, 4, &rng), -1);      /* 1-frame block */
    assert_int_equal(tcb_pair_sample(TCB_PAIRS_NEIGHBORS, 1, 10, 8, 11, 9, &rng), -1);  /* block past n */
}

static const tcb_block two_blocks[] = {{"50002", 0, 3}, {"50004", 3, 6}};

/* §5.2 with blocks: i uniform over all frames, j inside i's block, and the
 * file records the blocks. */
static void test_blocks_split(void **state)
{
    const char *dir = *state;
    enum { P = 9000 };
    tcb_split s, t;
    tcb_error err = {0};
    assert_int_equal(tcb_split_make("dfaust", "hips", TCB_ROLE_TEST, 9, two_blocks, 2, P, 5, &s, &err),
                     TCB_OK);
    int count[9] = {0};
    for (int p = 0; p < P; p++) {
        int i = s.pairs[2 * p], j = s.pairs[2 * p + 1];
        assert_int_not_equal(i, j);
        assert_int_equal(i < 3, j < 3);
        count[i]++;
    }
    for (int f = 0; f < 9; f++) assert_in_range(count[f], P / 9 - 150, P / 9 + 150); /* ~5 sigma */
    char path[512], *text;
    snprintf(path, sizeof path, "%s/hips.json", dir);
    assert_int_equal(tcb_split_save(path, &s, &err), TCB_OK);
    assert_int_equal(tcb_split_load(path, &t, &err), TCB_OK);
    assert_int_equal(t.n_blocks, 2);
    assert_string_equal(t.blocks[1].name, "50004");
    assert_int_equal(t.blocks[1].start, 3);
    assert_int_equal(t.blocks[1].n_frames, 6);
    assert_memory_equal(s.pairs, t.pairs, P * 2 * sizeof(int32_t));
    assert_int_equal(tcb_read_file(path, &text, NULL, &err), TCB_OK);
    assert_non_null(strstr(text, "\"blocks\""));
    free(text);
    tcb_split_free(&s), tcb_split_free(&t);

    /* One block draws what a block-less split over the same frames draws. */
    static const tcb_block whole[] = {{"50002", 0, 9}};
    make_ok("hips", TCB_ROLE_TEST, 9, 100, 5, &s);
    assert_int_equal(tcb_split_make("anim", "hips", TCB_ROLE_TEST, 9, whole, 1, 100, 5, &t, &err), TCB_OK);
    assert_memory_equal(s.pairs, t.pairs, 100 * 2 * sizeof(int32_t));
    tcb_split_free(&s), tcb_split_free(&t);
}

/* The split of 9 frames at path asked for with other blocks: refused,
 * naming the file and `field`. */
static void expect_blocks_refused(const char *path, const tcb_block *blocks, int n_blocks, const char *field)
{
    tcb_split s;
    tcb_error err = {0};
    expect_error(tcb_split_obtain(path, "d", "hips", TCB_ROLE_TEST, 9, blocks, n_blocks, 20, 3, &s, &err), &err,
                 TCB_ERR_INPUT, path, field);
    assert_null(s.pairs);
}

static void test_blocks_disagreement(void **state)
{
    char path[512];
    snprintf(path, sizeof path, "%s/hips.json", (const char *)*state);
    tcb_split s;
    tcb_error err = {0};
    for (int k = 0; k < 2; k++) { /* made, then reused */
        assert_int_equal(tcb_split_obtain(path, "d", "hips", TCB_ROLE_TEST, 9, two_blocks, 2, 20, 3, &s, &err),
                         TCB_OK);
        tcb_split_free(&s);
    }
    static const tcb_block moved[] = {{"50002", 0, 4}, {"50004", 4, 5}};
    static const tcb_block renamed[] = {{"50002", 0, 3}, {"50007", 3, 6}};
    expect_blocks_refused(path, moved, 2, "blocks[0] is \"50002\" frames [0, 3)");
    expect_blocks_refused(path, renamed, 2, "blocks[1] is \"50004\"");
    expect_blocks_refused(path, NULL, 0, "blocks is 2 blocks in the split file but no blocks");
    /* malformed requests: blocks that do not tile the frames */
    static const tcb_block gap[] = {{"a", 0, 3}, {"b", 4, 5}};
    static const tcb_block dup[] = {{"a", 0, 3}, {"a", 3, 6}};
    static const tcb_block one[] = {{"a", 0, 8}, {"b", 8, 1}};
    expect_error(tcb_split_make("d", "x", TCB_ROLE_TEST, 9, gap, 2, 5, 0, &s, &err), &err, TCB_ERR_INPUT,
                 "blocks[1].start", NULL);
    expect_error(tcb_split_make("d", "x", TCB_ROLE_TEST, 9, dup, 2, 5, 0, &s, &err), &err, TCB_ERR_INPUT,
                 "blocks[1].name", NULL);
    expect_error(tcb_split_make("d", "x", TCB_ROLE_TEST, 9, one, 2, 5, 0, &s, &err), &err, TCB_ERR_INPUT,
                 "blocks[1].n_frames", NULL);
    expect_error(tcb_split_make("d", "x", TCB_ROLE_TEST, 10, two_blocks, 2, 5, 0, &s, &err), &err,
                 TCB_ERR_INPUT, "cover 9 frames of 10", NULL);
}

/* A split file's blocks are checked like its pairs. */
static void test_blocks_malformed(void **state)
{
    const char *dir = *state;
#define HEAD                                                                                 \
    "{\"format\": \"tcbench-split/1\", \"dataset\": \"d\", \"sequence\": \"s\", \"role\": \"test\", " \
    "\"n_frames\": 4, \"seed\": 1, \"n_pairs\": 1, "
    static const struct {
        const char *json, *key;
    } cases[] = {
        {HEAD "\"blocks\": [], \"pairs\": [[0, 1]]}", ".blocks"},
        {HEAD "\"blocks\": {}, \"pairs\": [[0, 1]]}", ".blocks"},
        {HEAD "\"blocks\": [{\"name\": \"a\", \"start\": 0}], \"pairs\": [[0, 1]]}", ".blocks[0].n_frames"},
        {HEAD "\"blocks\": [{\"name\": \"a\", \"start\": 0, \"n_frames\": 4, \"x\": 1}], "
              "\"pairs\": [[0, 1]]}",
         ".blocks[0].x"},
        {HEAD "\"blocks\": [{\"name\": \"a\", \"start\": 0, \"n_frames\": 3}], \"pairs\": [[0, 1]]}",
         ".blocks: the blocks cover 3"},
        {HEAD "\"blocks\": [{\"name\": \"a\", \"start\": 0, \"n_frames\": 2}, "
              "{\"name\": \"b\", \"start\": 2, \"n_frames\": 2}], \"pairs\": [[1, 2]]}",
         ".pairs[0]: frames 1 and 2 are in different blocks"},
    };
#undef HEAD
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        char path[512];
        tu_write_text(dir, "bad.json", cases[c].json, path, sizeof path);
        tcb_split s;
        tcb_error err = {0};
        expect_error(tcb_split_load(path, &s, &err), &err, TCB_ERR_INPUT, path, cases[c].key);
        assert_null(s.pairs);
        assert_null(s.blocks);
    }
}

/* ------------------------------------------------------------ clip splits */

static void clips_ok(const char *seq, int n_frames, const tcb_block *blocks, int n_blocks, int n_clips,
                     uint64_t seed, tcb_split *s)
{
    tcb_error err = {0};
    if (tcb_clips_make("anim", seq, TCB_ROLE_TEST, n_frames, blocks, n_blocks, n_clips, seed, s, &err))
        fail_msg("clips: %s", err.msg);
}

/* The same request draws the same starts; another seed or sequence others;
 * every clip lies in one block, starts ascending and distinct; every valid
 * start is drawn about equally often over seeds (without replacement, all
 * of them when fewer than asked). */
static void test_clips_make(void **state)
{
    (void)state;
    tcb_split a, b, c, d;
    clips_ok("cat_walk", 60, NULL, 0, 10, 2021, &a);
    clips_ok("cat_walk", 60, NULL, 0, 10, 2021, &b);
    clips_ok("cat_walk", 60, NULL, 0, 10, 2022, &c);
    clips_ok("horse", 60, NULL, 0, 10, 2021, &d);
    assert_int_equal(a.n_clips, 10);
    assert_int_equal(a.clip_frames, TCB_CLIP_FRAMES);
    assert_int_equal(a.n_pairs, 0);
    assert_memory_equal(a.starts, b.starts, 10 * sizeof(int32_t));
    assert_memory_not_equal(a.starts, c.starts, 10 * sizeof(int32_t));
    assert_memory_not_equal(a.starts, d.starts, 10 * sizeof(int32_t));
    for (int k = 0; k < 10; k++) {
        assert_in_range(a.starts[k], 0, 60 - TCB_CLIP_FRAMES);
        if (k) assert_true(a.starts[k] > a.starts[k - 1]);
    }
    tcb_split_free(&a), tcb_split_free(&b), tcb_split_free(&c), tcb_split_free(&d);

    /* 44 valid starts, 4 drawn per seed: each 400 * 4 / 44 ≈ 36 times */
    int count[44] = {0};
    for (uint64_t seed = 0; seed < 400; seed++) {
        clips_ok("cat_walk", 60, NULL, 0, 4, seed, &a);
        for (int k = 0; k < 4; k++) count[a.starts[k]]++;
        tcb_split_free(&a);
    }
    for (int s = 0; s < 44; s++) assert_in_range(count[s], 15, 60);

    /* Two blocks of 20 and 18 frames: starts 0..3 and 20..21, all six. */
    const tcb_block blocks[] = {{"a", 0, 20}, {"b", 20, 18}};
    clips_ok("dfaust_seq", 38, blocks, 2, 10, 1, &a);
    assert_int_equal(a.n_clips, 6);
    const int32_t all[] = {0, 1, 2, 3, 20, 21};
    assert_memory_equal(a.starts, all, sizeof all);
    tcb_split_free(&a);

    tcb_error err = {0};
    expect_error(tcb_clips_make("anim", "short", TCB_ROLE_TEST, 16, NULL, 0, 10, 1, &a, &err), &err,
                 TCB_ERR_INPUT, "clips anim/short", "no 17 consecutive frames");
    assert_null(a.starts);
    const tcb_block small[] = {{"a", 0, 16}, {"b", 16, 16}};
    expect_error(tcb_clips_make("anim", "s", TCB_ROLE_TEST, 32, small, 2, 10, 1, &a, &err), &err,
                 TCB_ERR_INPUT, "in blocks", NULL);
    expect_error(tcb_clips_make("anim", "s", TCB_ROLE_TEST, 32, NULL, 0, 0, 1, &a, &err), &err,
                 TCB_ERR_INPUT, "at least one clip", NULL);
}

/* Saved and loaded back the same; obtained twice the same file; a request
 * that disagrees is refused naming the field. */
static void test_clips_file(void **state)
{
    const char *dir = *state;
    char path[512];
    snprintf(path, sizeof path, "%s/splits/anim/cat.clips.json", dir);
    tcb_split a, b;
    tcb_error err = {0};
    assert_int_equal(tcb_clips_obtain(path, "anim", "cat", TCB_ROLE_TEST, 35, NULL, 0, 5, 7, &a, &err), TCB_OK);
    assert_int_equal(tcb_split_load(path, &b, &err), TCB_OK);
    assert_int_equal(b.clip_frames, TCB_CLIP_FRAMES);
    assert_int_equal(b.n_clips, 5);
    assert_null(b.pairs);
    assert_memory_equal(a.starts, b.starts, 5 * sizeof(int32_t));
    tcb_split_free(&b);
    assert_int_equal(tcb_clips_obtain(path, "anim", "cat", TCB_ROLE_TEST, 35, NULL, 0, 5, 7, &b, &err), TCB_OK);
    assert_memory_equal(a.starts, b.starts, 5 * sizeof(int32_t));
    tcb_split_free(&a), tcb_split_free(&b);
    expect_error(tcb_clips_obtain(path, "anim", "cat", TCB_ROLE_TEST, 35, NULL, 0, 6, 7, &a, &err), &err,
                 TCB_ERR_INPUT, path, "n_clips");
    expect_error(tcb_clips_obtain(path, "anim", "cat", TCB_ROLE_TEST, 35, NULL, 0, 5, 8, &a, &err), &err,
                 TCB_ERR_INPUT, path, "seed");
    /* A pair split where a clip split is asked for, and the reverse. */
    expect_error(tcb_split_obtain(path, "anim", "cat", TCB_ROLE_TEST, 35, NULL, 0, 0, 7, &a, &err), &err,
                 TCB_ERR_INPUT, path, "clip_frames");
}

static void test_clips_malformed(void **state)
{
    const char *dir = *state;
#define HEAD                                                                                 \
    "{\"format\": \"tcbench-clips/1\", \"dataset\": \"d\", \"sequence\": \"s\", \"role\": \"test\", " \
    "\"n_frames\": 40, \"seed\": 1, "
    static const struct {
        const char *json, *key;
    } cases[] = {
        {HEAD "\"clip_frames\": 17, \"n_clips\": 2, \"starts\": [0, 24]}", ".starts[1]: the clip of 17 frames from 24"},
        {HEAD "\"clip_frames\": 17, \"n_clips\": 2, \"starts\": [5, 5]}", ".starts[1]: 5 does not follow 5"},
        {HEAD "\"clip_frames\": 17, \"n_clips\": 2, \"starts\": [5, 2]}", ".starts[1]"},
        {HEAD "\"clip_frames\": 17, \"n_clips\": 2, \"starts\": [5]}", ".starts: 1 starts but n_clips is 2"},
        {HEAD "\"clip_frames\": 17, \"n_clips\": 1, \"starts\": [-1]}", ".starts[0]"},
        {HEAD "\"clip_frames\": 17, \"n_clips\": 1, \"starts\": [1.5]}", ".starts[0]"},
        {HEAD "\"clip_frames\": 17, \"n_clips\": 0, \"starts\": []}", ".n_clips"},
        {HEAD "\"clip_frames\": 41, \"n_clips\": 1, \"starts\": [0]}", ".clip_frames"},
        {HEAD "\"n_clips\": 1, \"starts\": [0]}", ".clip_frames"},
        {HEAD "\"clip_frames\": 17, \"n_clips\": 1, \"starts\": [0], \"pairs\": []}", ".pairs"},
        {HEAD "\"clip_frames\": 17, \"n_clips\": 1, \"starts\": {}}", ".starts"},
        {HEAD "\"blocks\": [{\"name\": \"a\", \"start\": 0, \"n_frames\": 20}, {\"name\": \"b\", \"start\": 20, "
              "\"n_frames\": 20}], \"clip_frames\": 17, \"n_clips\": 1, \"starts\": [10]}",
         ".starts[0]: the clip of 17 frames from 10 ends past frame 19 (its block's last)"},
    };
#undef HEAD
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        char path[512];
        tu_write_text(dir, "bad.clips.json", cases[c].json, path, sizeof path);
        tcb_split s;
        tcb_error err = {0};
        expect_error(tcb_split_load(path, &s, &err), &err, TCB_ERR_INPUT, path, cases[c].key);
        assert_null(s.starts);
        assert_null(s.blocks);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_make_deterministic_and_valid),
        cmocka_unit_test(test_make_uniform),
        cmocka_unit_test(test_make_rejects),
        cmocka_unit_test(test_save_load_roundtrip),
        cmocka_unit_test(test_obtain_reuses),
        cmocka_unit_test(test_obtain_disagreement),
        cmocka_unit_test(test_load_malformed),
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_pair_samplers),
        cmocka_unit_test_setup_teardown(test_blocks_split, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_blocks_disagreement, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_blocks_malformed, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_clips_make),
        cmocka_unit_test_setup_teardown(test_clips_file, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_clips_malformed, tu_setup_tmpdir, tu_teardown_tmpdir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

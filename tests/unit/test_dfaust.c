/* DFAUST: registration files written here in the official layout
 * (support/dfaust_files.h: "<subject>_<sequence>" float (V, 3, F), frames on
 * the last axis, and "faces"), with two synthetic humanoids as subjects
 * 50007 (registrations_m.hdf5, 7 frames) and 50004 (registrations_f.hdf5,
 * 5 frames; first in the sorted order). Read back, blocks, subject
 * selection, the cache, the split and the samplers inside blocks, and every
 * malformed file an error naming the file and the dataset. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dfaust_files.h"
#include "methods/cycle/triplets.h"
#include "testutil.h"
#include "tcb/dfaust.h"
#include "tcb/fsutil.h"
#include "tcb/split.h"

#define SEQ "jumping_jacks"
#define FRAMES_M 7 /* subject 50007 */
#define FRAMES_F 5 /* subject 50004 */

static void file_path(const char *dir, const char *name, char *out, size_t size)
{
    assert_true((size_t)snprintf(out, size, "%s/%s", dir, name) < size);
}

/* registrations_m.hdf5: 50007 jumping_jacks and hips, the faces. */
static void write_m(const char *dir, const tcb_sequence *m)
{
    char path[TCB_PATH_MAX];
    file_path(dir, TCB_DFAUST_FILE_M, path, sizeof path);
    hid_t file = tu_h5_create(path);
    tu_dfaust_write_subject(file, "50007", SEQ, m);
    tu_dfaust_write_subject(file, "50007", "hips", m);
    tu_dfaust_write_faces(file, m);
    tu_h5_close(file);
}

/* registrations_f.hdf5 begun afresh: the rest is the caller's to add.
 * 50021_shake_hips is there to be ignored by sequence "hips". */
static hid_t begin_f(const char *dir, const tcb_sequence *f)
{
    char path[TCB_PATH_MAX];
    file_path(dir, TCB_DFAUST_FILE_F, path, sizeof path);
    hid_t file = tu_h5_create(path);
    tu_dfaust_write_subject(file, "50021", "shake_hips", f);
    return file;
}

/* registrations_f.hdf5 with subject 50004's registration as given. */
static void write_f(const char *dir, const tcb_sequence *f, hid_t type, int rank, const hsize_t *dims,
                    const void *data)
{
    hid_t file = begin_f(dir, f);
    tu_h5_write(file, "50004_" SEQ, type, rank, dims, data);
    tu_dfaust_write_faces(file, f);
    tu_h5_close(file);
}

static void write_root(const char *dir, const tcb_sequence *m, const tcb_sequence *f)
{
    write_m(dir, m);
    hid_t file = begin_f(dir, f);
    tu_dfaust_write_subject(file, "50004", SEQ, f);
    tu_dfaust_write_faces(file, f);
    tu_h5_close(file);
}

/* Each test's temporary directory, holding the root write_root makes, and
 * the two subjects' raw frames as written. */
typedef struct fixture {
    char dir[TCB_PATH_MAX];
    tcb_sequence m, f;
} fixture;

static int setup(void **state)
{
    fixture *fx = calloc(1, sizeof *fx);
    assert_non_null(fx);
    tu_make_tmpdir(fx->dir, sizeof fx->dir);
    tu_dfaust_subject_frames(1, FRAMES_M, &fx->m);
    tu_dfaust_subject_frames(0, FRAMES_F, &fx->f);
    write_root(fx->dir, &fx->m, &fx->f);
    *state = fx;
    return 0;
}

static int teardown(void **state)
{
    fixture *fx = *state;
    tu_remove_tree(fx->dir);
    tcb_sequence_free(&fx->m);
    tcb_sequence_free(&fx->f);
    free(fx);
    return 0;
}

static void read_ok(const char *dir, const char *seq, char *const *names, int n, tcb_sequence *out)
{
    tcb_error err = {0};
    if (tcb_dfaust_read(dir, seq, names, n, out, &err)) fail_msg("read: %s", err.msg);
}

/* Frames [start, start + n) of got are src's frames, bit for bit. */
static void assert_block(const tcb_sequence *got, int k, const char *name, int start, const tcb_sequence *src)
{
    assert_string_equal(got->blocks[k].name, name);
    assert_int_equal(got->blocks[k].start, start);
    assert_int_equal(got->blocks[k].n_frames, src->n_frames);
    assert_memory_equal(tcb_seq_frame(got, start), src->verts,
                        (size_t)src->n_frames * (size_t)src->n_verts * 3 * sizeof(float));
}

static void test_read_back(void **state)
{
    const fixture *fx = *state;
    const char *dir = fx->dir;
    tcb_sequence seq;
    read_ok(dir, SEQ, NULL, 0, &seq);
    assert_string_equal(seq.name, SEQ);
    assert_int_equal(seq.n_frames, FRAMES_M + FRAMES_F);
    assert_int_equal(seq.n_verts, fx->m.n_verts);
    assert_int_equal(seq.n_faces, fx->m.n_faces);
    assert_memory_equal(seq.faces, fx->m.faces, 3 * (size_t)seq.n_faces * sizeof(int32_t));
    assert_int_equal(seq.n_blocks, 2); /* sorted, whatever file they are in */
    assert_block(&seq, 0, "50004", 0, &fx->f);
    assert_block(&seq, 1, "50007", FRAMES_F, &fx->m);
    int lo, hi;
    assert_int_equal(tcb_seq_block_of(&seq, FRAMES_F - 1, &lo, &hi), 0);
    assert_true(lo == 0 && hi == FRAMES_F);
    assert_int_equal(tcb_seq_block_of(&seq, FRAMES_F, &lo, &hi), 1);
    assert_true(lo == FRAMES_F && hi == FRAMES_F + FRAMES_M);
    tcb_sequence_free(&seq);

    /* "hips" is 50007's only: 50021_shake_hips is another sequence */
    read_ok(dir, "hips", NULL, 0, &seq);
    assert_int_equal(seq.n_blocks, 1);
    assert_block(&seq, 0, "50007", 0, &fx->m);
    tcb_sequence_free(&seq);
}

static void test_subject_selection(void **state)
{
    const fixture *fx = *state;
    const char *dir = fx->dir;
    char *one[] = {"50004"}, *both[] = {"50007", "50004"};
    tcb_sequence seq;
    read_ok(dir, SEQ, one, 1, &seq);
    assert_int_equal(seq.n_frames, FRAMES_F);
    assert_int_equal(seq.n_blocks, 1);
    assert_block(&seq, 0, "50004", 0, &fx->f);
    tcb_sequence_free(&seq);
    read_ok(dir, SEQ, both, 2, &seq); /* the listed order */
    assert_block(&seq, 0, "50007", 0, &fx->m);
    assert_block(&seq, 1, "50004", FRAMES_M, &fx->f);
    tcb_sequence_free(&seq);

    /* one file is enough when it holds every subject asked for */
    char path[TCB_PATH_MAX];
    file_path(dir, TCB_DFAUST_FILE_F, path, sizeof path);
    assert_int_equal(unlink(path), 0);
    read_ok(dir, SEQ, NULL, 0, &seq);
    assert_int_equal(seq.n_blocks, 1);
    assert_block(&seq, 0, "50007", 0, &fx->m);
    tcb_sequence_free(&seq);
}

static void load(const char *dir, const char *cache, tcb_sequence *out)
{
    tcb_load_opts o = {TCB_NORM_NONE, 64, 7, cache, 0, NULL};
    tcb_error err = {0};
    if (tcb_sequence_load_dfaust(dir, SEQ, NULL, 0, &o, out, &err)) fail_msg("load: %s", err.msg);
}

/* §1.3: raw coordinates; the cache restores the blocks. */
static void test_load_through_cache(void **state)
{
    const fixture *fx = *state;
    const char *dir = fx->dir;
    char cache[TCB_PATH_MAX];
    file_path(dir, "cache", cache, sizeof cache);
    tcb_sequence plain, first, again;
    load(dir, NULL, &plain);
    assert_block(&plain, 0, "50004", 0, &fx->f); /* no scaling, no centring */
    assert_block(&plain, 1, "50007", FRAMES_F, &fx->m);
    assert_int_equal(plain.pool_size, 64);
    load(dir, cache, &first);
    load(dir, cache, &again);
    const tcb_sequence *seqs[] = {&first, &again};
    for (int k = 0; k < 2; k++) {
        assert_int_equal(seqs[k]->n_blocks, 2);
        assert_memory_equal(seqs[k]->blocks, plain.blocks, 2 * sizeof *plain.blocks);
        assert_memory_equal(seqs[k]->pools, plain.pools, (size_t)plain.n_frames * 64 * 3 * sizeof(float));
        assert_memory_equal(seqs[k]->verts, plain.verts,
                            (size_t)plain.n_frames * (size_t)plain.n_verts * 3 * sizeof(float));
    }
    tcb_sequence_free(&plain), tcb_sequence_free(&first), tcb_sequence_free(&again);
}

/* §5.2: the pairs stay in blocks, and the split file records them. */
static void test_split_in_blocks(void **state)
{
    const fixture *fx = *state;
    const char *dir = fx->dir;
    tcb_sequence seq;
    read_ok(dir, SEQ, NULL, 0, &seq);
    char path[TCB_PATH_MAX];
    file_path(dir, "split.json", path, sizeof path);
    tcb_split split, back;
    tcb_error err = {0};
    assert_int_equal(tcb_split_obtain(path, "dfaust", SEQ, TCB_ROLE_VALIDATION, seq.n_frames, seq.blocks,
                                      seq.n_blocks, 500, 2021, &split, &err),
                     TCB_OK);
    int crossed = 0, in_f = 0;
    for (int p = 0; p < 500; p++) {
        int lo, hi, i = split.pairs[2 * p], j = split.pairs[2 * p + 1];
        tcb_seq_block_of(&seq, i, &lo, &hi);
        crossed += j < lo || j >= hi || i == j;
        in_f += i < FRAMES_F;
    }
    assert_int_equal(crossed, 0);
    assert_in_range(in_f, 150, 270); /* i uniform over all 12 frames: 5/12 of 500 ≈ 208 */
    assert_int_equal(tcb_split_load(path, &back, &err), TCB_OK);
    assert_int_equal(back.n_blocks, 2);
    assert_memory_equal(back.blocks, seq.blocks, 2 * sizeof *seq.blocks);
    tcb_split_free(&back);
    tcb_split_free(&split);

    /* the same split for other subjects is refused, naming the field */
    char *one[] = {"50007"};
    tcb_sequence fewer;
    read_ok(dir, SEQ, one, 1, &fewer);
    assert_int_equal(tcb_split_obtain(path, "dfaust", SEQ, TCB_ROLE_VALIDATION, fewer.n_frames, fewer.blocks,
                                      fewer.n_blocks, 500, 2021, &split, &err),
                     TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, "n_frames"));
    tcb_sequence_free(&fewer);
    tcb_sequence_free(&seq);
}

/* §1.4: neighbors windows (atlas, CC) stay in i's block, random does not. */
static void test_samplers_in_blocks(void **state)
{
    const fixture *fx = *state;
    const char *dir = fx->dir;
    tcb_sequence seq;
    load(dir, NULL, &seq);
    tcb_rng rng;
    tcb_rng_seed(&rng, 3);
    int crossed_random = 0;
    for (int t = 0; t < 2000; t++) {
        int lo, hi, i = (int)tcb_rng_below(&rng, (uint32_t)seq.n_frames);
        tcb_seq_block_of(&seq, i, &lo, &hi);
        int j = tcb_pair_sample(TCB_PAIRS_NEIGHBORS, 5, seq.n_frames, lo, hi, i, &rng);
        assert_true(j >= lo && j < hi && j != i && abs(j - i) <= 5);
        j = tcb_pair_sample(TCB_PAIRS_RANDOM, 5, seq.n_frames, lo, hi, i, &rng);
        crossed_random += j < lo || j >= hi;
    }
    assert_true(crossed_random > 0);

    static const tcb_cc_sampling modes[] = {TCB_CC_SAMPLE_NEIGHBORS, TCB_CC_SAMPLE_KNN};
    for (int m = 0; m < 2; m++) {
        tcb_cc_sampler_opts o = tcb_cc_sampler_opts_default();
        o.sampling = modes[m], o.delta = 3, o.knn_points = 32;
        tcb_cc_sampler *smp;
        tcb_error err = {0};
        if (tcb_cc_sampler_create(&seq, &o, &smp, &err)) fail_msg("cc sampler: %s", err.msg);
        for (int t = 0; t < 2000; t++) {
            int abc[3], lo, hi;
            tcb_cc_sampler_draw(smp, &rng, abc);
            tcb_seq_block_of(&seq, abc[0], &lo, &hi);
            for (int k = 1; k < 3; k++) assert_true(abc[k] >= lo && abc[k] < hi);
        }
        tcb_cc_sampler_free(smp);
    }
    tcb_sequence_free(&seq);
}

/* ---- malformed roots: each an error naming the file and the dataset ---- */

static void expect_error(const char *dir, char *const *names, int n, const char *seq, int code,
                         const char *file, const char *key)
{
    tcb_sequence out;
    tcb_error err = {0};
    assert_int_equal(tcb_dfaust_read(dir, seq, names, n, &out, &err), code);
    char path[TCB_PATH_MAX];
    file_path(dir, file, path, sizeof path);
    if (!strstr(err.msg, path)) fail_msg("'%s' does not name %s", err.msg, path);
    if (key && !strstr(err.msg, key)) fail_msg("'%s' does not name %s", err.msg, key);
    assert_null(out.verts);
    assert_null(out.blocks);
}

static void test_truncated_file(void **state)
{
    const fixture *fx = *state;
    const char *dir = fx->dir;
    char path[TCB_PATH_MAX];
    file_path(dir, TCB_DFAUST_FILE_F, path, sizeof path);
    long long size;
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    fseek(fp, 0, SEEK_END);
    size = ftell(fp);
    fclose(fp);
    assert_int_equal(truncate(path, size / 2), 0);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "<subject>_" SEQ);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "truncated");
}

static void test_wrong_shapes(void **state)
{
    const fixture *fx = *state;
    const char *dir = fx->dir, *key = "50004_" SEQ;
    hsize_t V = (hsize_t)fx->f.n_verts;
    float *data = tu_falloc(V * 4 * FRAMES_F);
    const hsize_t rank2[2] = {V, 3}, four[3] = {V, 4, FRAMES_F}, one[3] = {V, 3, 1};
    const hsize_t fewer[3] = {V - 1, 3, FRAMES_F};
    write_f(dir, &fx->f, H5T_NATIVE_FLOAT, 2, rank2, data);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, key);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "(V, 3, F), got a float array of shape (");
    write_f(dir, &fx->f, H5T_NATIVE_FLOAT, 3, four, data);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, key);
    write_f(dir, &fx->f, H5T_NATIVE_INT32, 3, four, data);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "got an integer array");
    write_f(dir, &fx->f, H5T_NATIVE_FLOAT, 3, one, data);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "at least 2");
    write_f(dir, &fx->f, H5T_NATIVE_FLOAT, 3, fewer, data);
    char *m_first[] = {"50007", "50004"};
    expect_error(dir, m_first, 2, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "vertices, but the first subject has");
    free(data);
}

/* registrations_f.hdf5 with 50004 as written and `faces` as given. */
static void write_f_faces(const char *dir, const tcb_sequence *f, int rank, const hsize_t *dims,
                          const int32_t *faces)
{
    hid_t file = begin_f(dir, f);
    tu_dfaust_write_subject(file, "50004", SEQ, f);
    tu_h5_write(file, "faces", H5T_NATIVE_INT32, rank, dims, faces);
    tu_h5_close(file);
}

static void test_bad_faces(void **state)
{
    const fixture *fx = *state;
    const char *dir = fx->dir;
    hid_t file = begin_f(dir, &fx->f); /* no faces */
    tu_dfaust_write_subject(file, "50004", SEQ, &fx->f);
    tu_h5_close(file);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "no dataset faces");
    char *m_only[] = {"50007"};
    tcb_sequence seq;
    read_ok(dir, SEQ, m_only, 1, &seq); /* a file no subject comes from is not read */
    tcb_sequence_free(&seq);

    size_t n = 3 * (size_t)fx->f.n_faces;
    int32_t *faces = malloc(n * sizeof *faces);
    assert_non_null(faces);
    memcpy(faces, fx->f.faces, n * sizeof *faces);
    faces[n - 2] = fx->f.n_verts; /* one past the last vertex */
    const hsize_t dims[2] = {(hsize_t)fx->f.n_faces, 3}, flat[1] = {n};
    write_f_faces(dir, &fx->f, 2, dims, faces);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "faces[");
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "outside [0, ");
    faces[n - 2] = fx->f.faces[n - 1], faces[n - 1] = fx->f.faces[n - 2]; /* in range, but other faces */
    write_f_faces(dir, &fx->f, 2, dims, faces);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "faces differ");
    write_f_faces(dir, &fx->f, 1, flat, faces);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "faces: expected an integer array");
    free(faces);
}

static void test_missing_subjects(void **state)
{
    const fixture *fx = *state;
    const char *dir = fx->dir;
    char *listed[] = {"50007", "50099"};
    expect_error(dir, listed, 2, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_M, "no dataset 50099_" SEQ);
    expect_error(dir, listed, 2, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "no dataset 50099_" SEQ);
    expect_error(dir, NULL, 0, "running_on_spot", TCB_ERR_INPUT, TCB_DFAUST_FILE_M,
                 "no dataset <subject>_running_on_spot");
    expect_error(dir, NULL, 0, "running_on_spot", TCB_ERR_INPUT, TCB_DFAUST_FILE_F, NULL);

    /* a subject in both files */
    hid_t file = begin_f(dir, &fx->f);
    tu_dfaust_write_subject(file, "50007", SEQ, &fx->f);
    tu_dfaust_write_faces(file, &fx->f);
    tu_h5_close(file);
    expect_error(dir, NULL, 0, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_F, "both hold dataset 50007_" SEQ);
    expect_error(dir, listed, 1, SEQ, TCB_ERR_INPUT, TCB_DFAUST_FILE_M, "both hold dataset 50007_" SEQ);

    char empty[TCB_PATH_MAX];
    file_path(dir, "empty", empty, sizeof empty);
    tcb_error err = {0};
    assert_int_equal(tcb_mkdirs(empty, &err), TCB_OK);
    tcb_sequence out;
    assert_int_equal(tcb_dfaust_read(empty, SEQ, NULL, 0, &out, &err), TCB_ERR_IO);
    assert_non_null(strstr(err.msg, TCB_DFAUST_FILE_M));
}

int main(void)
{
#define T(f) cmocka_unit_test_setup_teardown(f, setup, teardown)
    const struct CMUnitTest tests[] = {
        T(test_read_back),
        T(test_subject_selection),
        T(test_load_through_cache),
        T(test_split_in_blocks),
        T(test_samplers_in_blocks),
        T(test_truncated_file),
        T(test_wrong_shapes),
        T(test_bad_faces),
        T(test_missing_subjects),
    };
#undef T
    return cmocka_run_group_tests(tests, NULL, NULL);
}

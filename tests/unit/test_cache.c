/* HDF5 sequence cache: round trip, stale keys, corrupt files, and the
 * OBJ-directory loader that sits on top of it. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>
#include <dirent.h>
#include <fcntl.h>
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "tcb/fsutil.h"
#include "tcb/sequence.h"
#include "testutil.h"

/* dir/frames/mesh_000k.obj: a square pyramid that widens with k. */
static void write_frames(const char *dir, int n)
{
    char sub[TCB_PATH_MAX];
    snprintf(sub, sizeof sub, "%s/frames", dir);
    tcb_error err = {0};
    assert_int_equal(tcb_mkdirs(sub, &err), TCB_OK);
    for (int k = 0; k < n; k++) {
        char name[64], text[512], path[TCB_PATH_MAX];
        float w = 1.0f + 0.25f * k;
        snprintf(name, sizeof name, "mesh_%04d.obj", k);
        snprintf(text, sizeof text,
                 "v 0 0 0\nv %g 0 0\nv %g %g 0\nv 0 %g 0\nv %g %g 1.5\n"
                 "f 1 4 3 2\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n",
                 w, w, w, w, w / 2, w / 2);
        tu_write_text(sub, name, text, path, sizeof path);
    }
}

static void assert_same_sequence(const tcb_sequence *a, const tcb_sequence *b)
{
    assert_string_equal(a->name, b->name);
    assert_int_equal(a->n_frames, b->n_frames);
    assert_int_equal(a->n_verts, b->n_verts);
    assert_int_equal(a->n_faces, b->n_faces);
    assert_int_equal(a->pool_size, b->pool_size);
    assert_int_equal(a->norm, b->norm);
    assert_memory_equal(&a->norm_scale, &b->norm_scale, sizeof(double));
    size_t F = (size_t)a->n_frames;
    assert_memory_equal(a->verts, b->verts, sizeof(float) * 3 * F * (size_t)a->n_verts);
    assert_memory_equal(a->faces, b->faces, sizeof(int32_t) * 3 * (size_t)a->n_faces);
    assert_memory_equal(a->areas, b->areas, sizeof(double) * F);
    assert_memory_equal(a->norm_shift, b->norm_shift, sizeof(double) * 3 * F);
    assert_memory_equal(a->pools, b->pools, sizeof(float) * 3 * F * (size_t)a->pool_size);
    assert_int_equal(a->yaw != NULL, b->yaw != NULL);
    if (a->yaw) assert_memory_equal(a->yaw, b->yaw, sizeof(double) * F);
    assert_int_equal(a->n_blocks, b->n_blocks);
    if (a->n_blocks) assert_memory_equal(a->blocks, b->blocks, sizeof *a->blocks * (size_t)a->n_blocks);
}

static void load_fresh(const char *dir, tcb_sequence *s)
{
    char frames[TCB_PATH_MAX];
    snprintf(frames, sizeof frames, "%s/frames", dir);
    tcb_load_opts o = {TCB_NORM_FIRST_FRAME, 50, 3, NULL, 0, NULL};
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_load_objdir(frames, "pyramid", &o, s, &err), TCB_OK);
}

/* s saved to path under key, loaded back into *back and compared. */
static void save_and_reload(const char *path, const tcb_sequence *s, const char *key, tcb_sequence *back)
{
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_cache_save(path, s, key, &err), TCB_OK);
    assert_int_equal(tcb_sequence_cache_load(path, key, back, &err), TCB_OK);
    assert_same_sequence(s, back);
}

static void test_round_trip_bit_exact(void **state)
{
    const char *dir = *state;
    write_frames(dir, 4);
    tcb_sequence s, back;
    load_fresh(dir, &s);
    char path[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/cache/pyramid.h5", dir);
    tcb_error err = {0};
    save_and_reload(path, &s, "key-1", &back);
    tcb_sequence_free(&back);
    /* A different key is stale, not corrupt: the caller re-parses. */
    assert_int_equal(tcb_sequence_cache_load(path, "key-2", &back, &err), TCB_ERR_UNSUPPORTED);
    assert_non_null(strstr(err.msg, path));
    assert_null(back.verts);
    tcb_sequence_free(&s);
}

static void test_long_key(void **state)
{
    /* Keys grow with the frame count; one past HDF5's 64 KiB compact
     * attribute limit must still round-trip. */
    const char *dir = *state;
    write_frames(dir, 2);
    tcb_sequence s, back;
    load_fresh(dir, &s);
    size_t len = 200000;
    char *key = malloc(len + 1);
    for (size_t i = 0; i < len; i++) key[i] = (char)('a' + i % 26);
    key[len] = '\0';
    char path[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/long.h5", dir);
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_cache_save(path, &s, key, &err), TCB_OK);
    assert_int_equal(tcb_sequence_cache_load(path, key, &back, &err), TCB_OK);
    assert_same_sequence(&s, &back);
    key[len - 1] = '!';
    tcb_sequence_free(&back);
    assert_int_equal(tcb_sequence_cache_load(path, key, &back, &err), TCB_ERR_UNSUPPORTED);
    free(key);
    tcb_sequence_free(&s);
}

/* The blocks (DFAUST subjects) are stored and restored; blocks that do not
 * tile the frames make the file corrupt. */
static void test_blocks_round_trip(void **state)
{
    const char *dir = *state;
    write_frames(dir, 5);
    tcb_sequence s, back;
    load_fresh(dir, &s);
    s.blocks = calloc(2, sizeof *s.blocks);
    s.n_blocks = 2;
    s.blocks[0] = (tcb_block){"50002", 0, 2};
    s.blocks[1] = (tcb_block){"50004", 2, 3};
    char path[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/blocks.h5", dir);
    save_and_reload(path, &s, "k", &back);
    tcb_sequence_free(&back);
    tcb_error err = {0};
    s.blocks[1].n_frames = 2; /* frame 4 in no block */
    assert_int_equal(tcb_sequence_cache_save(path, &s, "k", &err), TCB_OK);
    assert_int_equal(tcb_sequence_cache_load(path, "k", &back, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "bad blocks"));
    assert_null(back.blocks);
    tcb_sequence_free(&s);
}

/* A cache written by the previous format (3, before blocks) is stale: the
 * caller parses afresh. */
static void test_old_format_is_stale(void **state)
{
    const char *dir = *state;
    write_frames(dir, 3);
    tcb_sequence s;
    load_fresh(dir, &s);
    char path[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/old.h5", dir);
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_cache_save(path, &s, "k", &err), TCB_OK);
    tcb_sequence_free(&s);
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t a = H5Aopen(f, "format_version", H5P_DEFAULT);
    const int old = 3;
    assert_true(f >= 0 && a >= 0 && H5Awrite(a, H5T_NATIVE_INT, &old) >= 0);
    H5Aclose(a), H5Fclose(f);
    assert_int_equal(tcb_sequence_cache_load(path, "k", &s, &err), TCB_ERR_UNSUPPORTED);
    assert_non_null(strstr(err.msg, "stale cache (format 3"));
}

static void expect_corrupt(const char *path, const char *why)
{
    tcb_sequence s;
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_cache_load(path, "k", &s, &err), TCB_ERR_INPUT);
    if (!strstr(err.msg, path) || !strstr(err.msg, why)) fail_msg("'%s' does not name %s and '%s'", err.msg, path, why);
    assert_null(s.verts);
}

static void test_corrupt_and_foreign_files(void **state)
{
    const char *dir = *state;
    char path[TCB_PATH_MAX];
    tu_write_text(dir, "text.h5", "this is not HDF5\n", path, sizeof path);
    expect_corrupt(path, "not an HDF5 file");

    /* A valid HDF5 file that is not a cache. */
    snprintf(path, sizeof path, "%s/foreign.h5", dir);
    hid_t f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(f >= 0);
    H5Fclose(f);
    expect_corrupt(path, "no format_version");

    /* A real cache cut in half. */
    write_frames(dir, 3);
    tcb_sequence s;
    load_fresh(dir, &s);
    snprintf(path, sizeof path, "%s/whole.h5", dir);
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_cache_save(path, &s, "k", &err), TCB_OK);
    tcb_sequence_free(&s);
    char *data;
    size_t len;
    assert_int_equal(tcb_read_file(path, &data, &len, &err), TCB_OK);
    snprintf(path, sizeof path, "%s/half.h5", dir);
    assert_int_equal(tcb_write_file_atomic(path, data, len / 2, &err), TCB_OK);
    free(data);
    expect_corrupt(path, "not a valid tcbench sequence cache");

    /* One vertex coordinate changed in place: HDF5 checksums its metadata,
     * not the data, so only the cache's own checksum sees it. */
    snprintf(path, sizeof path, "%s/whole.h5", dir);
    f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t ds = H5Dopen2(f, "verts", H5P_DEFAULT), space = H5Dget_space(ds);
    hsize_t at[3] = {1, 2, 0}, one = 1;
    float moved = 0.125f;
    hid_t mem = H5Screate_simple(1, &one, NULL);
    assert_true(f >= 0 && ds >= 0 && H5Sselect_elements(space, H5S_SELECT_SET, 1, at) >= 0 &&
                H5Dwrite(ds, H5T_NATIVE_FLOAT, mem, space, H5P_DEFAULT, &moved) >= 0);
    H5Sclose(mem), H5Sclose(space), H5Dclose(ds), H5Fclose(f);
    expect_corrupt(path, "checksum mismatch");

    snprintf(path, sizeof path, "%s/absent.h5", dir);
    assert_int_equal(tcb_sequence_cache_load(path, "k", &s, &err), TCB_ERR_IO);
    assert_non_null(strstr(err.msg, path));
}

/* Number of entries in dir; every one must be a finished .h5 file. */
static int count_cache_files(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) {
        if (e->d_name[0] == '.') continue;
        size_t len = strlen(e->d_name);
        if (len < 3 || strcmp(e->d_name + len - 3, ".h5") != 0) fail_msg("stray file %s", e->d_name);
        n++;
    }
    closedir(d);
    return n;
}

/* Overwrites a frame with same-size garbage and restores its mtime, so
 * only a loader that trusts the cache can still succeed. */
static void poison_keeping_stat(const char *path)
{
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    char *junk = malloc((size_t)st.st_size + 1);
    memset(junk, 'x', (size_t)st.st_size);
    junk[st.st_size] = '\0';
    FILE *f = fopen(path, "wb");
    fputs(junk, f);
    fclose(f);
    free(junk);
    struct timespec times[2] = {st.st_atim, st.st_mtim};
    assert_int_equal(utimensat(AT_FDCWD, path, times, 0), 0);
}

static void test_load_objdir_uses_cache(void **state)
{
    const char *dir = *state;
    write_frames(dir, 3);
    char frames[TCB_PATH_MAX], cache[TCB_PATH_MAX], frame0[TCB_PATH_MAX];
    snprintf(frames, sizeof frames, "%s/frames", dir);
    snprintf(cache, sizeof cache, "%s/cache", dir);
    snprintf(frame0, sizeof frame0, "%s/frames/mesh_0000.obj", dir);
    tcb_load_opts o = {TCB_NORM_PER_FRAME, 40, 11, cache, 0, NULL};
    tcb_sequence first, second, plain;
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_load_objdir(frames, NULL, &o, &first, &err), TCB_OK);
    assert_string_equal(first.name, "frames");
    assert_int_equal(count_cache_files(cache), 1);
    /* The cache holds exactly what an uncached load computes. */
    o.cache_dir = NULL;
    assert_int_equal(tcb_sequence_load_objdir(frames, NULL, &o, &plain, &err), TCB_OK);
    assert_same_sequence(&first, &plain);
    tcb_sequence_free(&plain);

    o.cache_dir = cache;
    poison_keeping_stat(frame0);
    assert_int_equal(tcb_sequence_load_objdir(frames, NULL, &o, &second, &err), TCB_OK);
    assert_same_sequence(&first, &second);
    tcb_sequence_free(&second);

    /* Other options make another entry, which needs the (now bad) OBJ. */
    o.pool_seed = 12;
    assert_int_equal(tcb_sequence_load_objdir(frames, NULL, &o, &second, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, frame0));
    o.pool_seed = 11, o.align_samples = 64;
    assert_int_equal(tcb_sequence_load_objdir(frames, NULL, &o, &second, &err), TCB_ERR_INPUT);
    assert_int_equal(count_cache_files(cache), 1);
    tcb_sequence_free(&first);
}

/* A rotation-aligned load caches its yaws with it. */
static void test_aligned_load_caches_yaw(void **state)
{
    const char *dir = *state;
    write_frames(dir, 4);
    char frames[TCB_PATH_MAX], cache[TCB_PATH_MAX];
    snprintf(frames, sizeof frames, "%s/frames", dir);
    snprintf(cache, sizeof cache, "%s/cache", dir);
    tcb_load_opts o = {TCB_NORM_PER_FRAME, 40, 11, cache, 64, NULL};
    tcb_sequence first, again, plain;
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_load_objdir(frames, NULL, &o, &first, &err), TCB_OK);
    assert_non_null(first.yaw);
    assert_int_equal(tcb_sequence_load_objdir(frames, NULL, &o, &again, &err), TCB_OK);
    assert_same_sequence(&first, &again);
    o.cache_dir = NULL;
    assert_int_equal(tcb_sequence_load_objdir(frames, NULL, &o, &plain, &err), TCB_OK);
    assert_same_sequence(&first, &plain);
    tcb_sequence_free(&first), tcb_sequence_free(&again), tcb_sequence_free(&plain);
}

static char last_log[1024];

static void on_log(void *ctx, tcb_log_level level, const char *msg)
{
    (void)ctx;
    assert_int_equal(level, TCB_LOG_WARN);
    snprintf(last_log, sizeof last_log, "%s", msg);
}

static void test_load_objdir_rebuilds_stale_entry(void **state)
{
    const char *dir = *state;
    write_frames(dir, 3);
    char frames[TCB_PATH_MAX], cache[TCB_PATH_MAX];
    snprintf(frames, sizeof frames, "%s/frames", dir);
    snprintf(cache, sizeof cache, "%s/cache", dir);
    tcb_load_opts o = {TCB_NORM_FIRST_FRAME, 0, 0, cache, 0, NULL}; /* 0: default pool size */
    tcb_sequence a, b;
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_load_objdir(frames, "p", &o, &a, &err), TCB_OK);
    assert_int_equal(a.pool_size, TCB_DEFAULT_POOL_SIZE);
    /* A changed frame (new size and mtime) must be re-parsed. */
    write_frames(dir, 4);
    assert_int_equal(tcb_sequence_load_objdir(frames, "p", &o, &b, &err), TCB_OK);
    assert_int_equal(b.n_frames, 4);
    assert_int_equal(count_cache_files(cache), 2);
    /* A corrupted entry is rebuilt, and said, naming it. */
    tcb_reporter said = {NULL, on_log, NULL};
    o.reporter = &said;
    DIR *d = opendir(cache);
    for (struct dirent *e; (e = readdir(d));) {
        if (e->d_name[0] == '.') continue;
        char path[TCB_PATH_MAX];
        tu_write_text(cache, e->d_name, "garbage", path, sizeof path);
    }
    closedir(d);
    tcb_sequence c;
    assert_int_equal(tcb_sequence_load_objdir(frames, "p", &o, &c, &err), TCB_OK);
    assert_same_sequence(&b, &c);
    if (!strstr(last_log, "sequence cache not reused: ") || !strstr(last_log, cache) ||
        !strstr(last_log, "not a valid tcbench sequence cache"))
        fail_msg("warning '%s'", last_log);
    tcb_sequence_free(&a);
    tcb_sequence_free(&b);
    tcb_sequence_free(&c);
}

int main(void)
{
#define T(f) cmocka_unit_test_setup_teardown(f, tu_setup_tmpdir, tu_teardown_tmpdir)
    const struct CMUnitTest tests[] = {
        T(test_round_trip_bit_exact),
        T(test_blocks_round_trip),
        T(test_old_format_is_stale),
        T(test_aligned_load_caches_yaw),
        T(test_long_key),
        T(test_corrupt_and_foreign_files),
        T(test_load_objdir_uses_cache),
        T(test_load_objdir_rebuilds_stale_entry),
    };
#undef T
    return cmocka_run_group_tests(tests, NULL, NULL);
}

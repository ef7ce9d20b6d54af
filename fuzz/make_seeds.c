/* Writes the seed corpora the build generates (the committed ones are
 * small text files under fuzz/seeds/): files the checkpoint targets'
 * objects accept, and HDF5 programs (h5_program.h) that build valid files.
 *   make_seeds OUT_DIR   → OUT_DIR/<target>/<seed>
 * Deterministic: the same build writes the same bytes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz/h5_names.h"
#include "fuzz/h5_program.h"
#include "fuzz/tiny.h"
#include "methods/atlas/train_ckpt.h"
#include "tcb/fsutil.h"
#include "tcb/registry.h"

static void ok(int rc, const tcb_error *err)
{
    if (rc == TCB_OK) return;
    fprintf(stderr, "make_seeds: %s\n", err->msg);
    exit(1);
}

static void path_of(char *out, const char *dir, const char *target, const char *name)
{
    tcb_error err = {0};
    ok(tcb_path_join(out, TCB_PATH_MAX, &err, "%s/%s/%s", dir, target, name), &err);
}

static void train_ckpt(const char *dir, const tcb_sequence *seq)
{
    tcb_atlas_model *model;
    tcb_atlas_trainer *t;
    fuzz_tiny_trainer(seq, &model, &t);
    char path[TCB_PATH_MAX];
    tcb_error err = {0};
    double loss;
    for (int it = 0; it < 2; it++) ok(tcb_atlas_train_step(t, seq, &loss, &err), &err);
    path_of(path, dir, "train_ckpt", "step2.ckpt");
    ok(tcb_atlas_train_ckpt_save(t, seq, FUZZ_TINY_SEED, 1.5, path, &err), &err);
    tcb_atlas_trainer_free(t);
    tcb_atlas_model_free(model);
}

/* The method fitted on seq and saved: what its load reads. */
static void fitted_model(const char *dir, const char *method, const tcb_sequence *seq)
{
    const tcb_method_ops *ops = tcb_registry_find(method);
    void *self = fuzz_tiny_method(method);
    char work[TCB_PATH_MAX], path[TCB_PATH_MAX];
    path_of(work, dir, "work", method);
    tcb_error err = {0};
    ok(tcb_mkdirs(work, &err), &err);
    tcb_fit_ctx ctx = {.seed = FUZZ_TINY_SEED, .n_threads = 1, .work_dir = work};
    ok(ops->fit(self, seq, &ctx, &err), &err);
    path_of(path, dir, method, "");
    ok(tcb_mkdirs(path, &err), &err);
    path_of(path, dir, method, "fitted.bin");
    ok(ops->save(self, path, &err), &err);
    ops->destroy(self);
}

/* The deform chain of frame 0 to FUZZ_DEFORM_NEAR and _FAR, as an
 * evaluation saves it. */
static void deform_chain(const char *dir, const tcb_sequence *seq)
{
    const tcb_method_ops *ops = tcb_registry_find("nricp");
    struct nricp_method *self = fuzz_tiny_deform(seq);
    char work[TCB_PATH_MAX];
    path_of(work, dir, "deform_chain", "");
    tcb_error err = {0};
    ok(tcb_mkdirs(work, &err), &err);
    tcb_fit_ctx ctx = {.seed = FUZZ_TINY_SEED, .n_threads = 1, .work_dir = work};
    static const int pairs[] = {0, FUZZ_DEFORM_NEAR, 0, FUZZ_DEFORM_FAR};
    ok(ops->prepare_pairs(self, seq, pairs, 0, 2, &ctx, &err), &err);
    ops->destroy(self);
}

static void write_program(const char *dir, const char *target, const char *name, const h5prog_buf *b)
{
    char path[TCB_PATH_MAX];
    path_of(path, dir, target, name);
    tcb_error err = {0};
    ok(tcb_write_file_atomic(path, b->bytes, b->len, &err), &err);
}

/* A tetrahedron over 3 frames, saved by the cache's own writer (its
 * checksum included) and turned into the program that rebuilds that file;
 * and the same program without the pools. */
static void cache_program(const char *dir)
{
    static const float verts[3][4][3] = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                         {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 2}},
                                         {{0, 0, 0}, {2, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    static const int32_t faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    tcb_sequence s;
    tcb_error err = {0};
    ok(tcb_sequence_alloc(&s, "tet", 3, 4, 4, &err), &err);
    memcpy(s.verts, verts, sizeof verts), memcpy(s.faces, faces, sizeof faces);
    const tcb_load_opts opts = {.norm = TCB_NORM_FIRST_FRAME, .pool_size = 8, .pool_seed = 1};
    ok(tcb_sequence_prepare(&s, &opts, &err), &err);
    char path[TCB_PATH_MAX];
    path_of(path, dir, "work", "tet.h5");
    ok(tcb_sequence_cache_save(path, &s, CACHE_KEY_TEXT, &err), &err);
    tcb_sequence_free(&s);
    h5prog_buf b = {0};
    h5prog_from_file(&b, path, cache_names, CACHE_N_NAMES);
    write_program(dir, "cache", "tetrahedron.prog", &b);
    free(b.bytes);
    const char *without_pools[CACHE_N_NAMES];
    for (int k = 0; k < CACHE_N_NAMES; k++) without_pools[k] = k == CACHE_POOLS ? "absent" : cache_names[k];
    h5prog_buf c = {0};
    h5prog_from_file(&c, path, without_pools, CACHE_N_NAMES);
    write_program(dir, "cache", "tetrahedron_checksum_mismatch.prog", &c);
    free(c.bytes);
    remove(path);
}

/* OBJ frames in the forms the reader accepts: plain, v/vt/vn with
 * polygons and relative indices, CRLF and comments. */
static void obj_seeds(const char *dir)
{
    static const char *const files[][2] = {
        {"tetrahedron.obj", "# a tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"},
        {"quad_forms.obj", "o quad\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                           "vn 0 0 1\ns off\nusemtl skin\nf 1/1/1 2/2/1 3/3/1 4/4/1\nf -4//1 -2//1 -1//1\n"},
        {"crlf_texcoords.obj", "v 0 0 0 1.0\nv 1e-3 0 0\nv 0 2.5e+1 0\r\nf 1/1 2/2 3/3 # comment\n\n"}};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        char path[TCB_PATH_MAX];
        path_of(path, dir, "obj", files[k][0]);
        tcb_error err = {0};
        ok(tcb_write_file_atomic(path, files[k][1], strlen(files[k][1]), &err), &err);
    }
}

/* Two subjects of a tetrahedron, (V, 3, F) = (4, 3, 2). */
static void dfaust_program(const char *dir)
{
    static const float regs[4][3][2] = {{{0, 0}, {0, 0}, {0, 0}}, {{1, 1}, {0, 0}, {0, 0}},
                                        {{0, 0}, {1, 1}, {0, 0}}, {{0, 0}, {0, 0}, {1, 2}}};
    static const int32_t faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    h5prog_buf b = {0};
    h5prog_add_array(&b, 0, DFAUST_FACES, H5P_I32, 2, (const int[]){4, 3}, faces);
    h5prog_add_array(&b, 0, DFAUST_50002, H5P_F32, 3, (const int[]){4, 3, 2}, regs);
    write_program(dir, "dfaust", "one_subject.prog", &b);
    h5prog_add_array(&b, 0, DFAUST_50004, H5P_F32, 3, (const int[]){4, 3, 2}, regs);
    write_program(dir, "dfaust", "two_subjects.prog", &b);
    free(b.bytes);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_seeds OUT_DIR\n");
        return 2;
    }
    /* dir/work: the fits' work directories and a scratch cache, removed at the end */
    char work[TCB_PATH_MAX];
    path_of(work, argv[1], "work", "");
    tcb_error err = {0};
    ok(tcb_mkdirs(work, &err), &err);
    tcb_sequence seq;
    fuzz_tiny_sequence(&seq);
    train_ckpt(argv[1], &seq);
    fitted_model(argv[1], "mca", &seq);
    fitted_model(argv[1], "cc", &seq);
    fitted_model(argv[1], "nricp", &seq);
    deform_chain(argv[1], &seq);
    tcb_sequence_free(&seq);
    cache_program(argv[1]);
    dfaust_program(argv[1]);
    obj_seeds(argv[1]);
    ok(tcb_empty_dir(work, &err), &err);
    remove(work);
    return 0;
}

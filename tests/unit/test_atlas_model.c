/* The atlas model's bookkeeping (methods/atlas/model.c): parameter counts and
 * layout, PyTorch-style init, determinism, the tangent-free path, weight
 * export/import; and the vectorized softplus against libm. The gradients
 * themselves are checked in test_atlas_grad.c. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/atlas/model.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"
#include "testutil.h"

enum { C = 16, P = 2, B = 2, N = 32, M = 14 };

static tcb_atlas_model *make_model(int c, int p, uint64_t seed)
{
    tcb_atlas_model *m;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_model_create(c, p, &m, &err), TCB_OK);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "test/atlas/init");
    tcb_atlas_model_init(m, &rng);
    return m;
}

/* reference-protocol §2.2: 2,239,872 encoder + 1,712,908 per patch. */
static void test_param_count(void **state)
{
    (void)state;
    assert_int_equal(tcb_atlas_param_count(1024, 1), 2239872 + 1712908);
    assert_int_equal(tcb_atlas_param_count(1024, 10), 19368952);
    assert_int_equal(tcb_atlas_param_count(1024, 10) - tcb_atlas_param_count(1024, 9), 1712908);
    /* the views tile the flat vector: encoder first, decoders in order */
    tcb_atlas_model *m = make_model(C, P, 1);
    size_t off = 0;
    for (int k = 0; k < TCB_ATLAS_ENC_LAYERS + P * TCB_ATLAS_DEC_LAYERS; k++) {
        const tcb_linear *l =
            k < TCB_ATLAS_ENC_LAYERS ? &m->enc.l[k]
                                     : &m->dec[(k - TCB_ATLAS_ENC_LAYERS) / TCB_ATLAS_DEC_LAYERS]
                                            .l[(k - TCB_ATLAS_ENC_LAYERS) % TCB_ATLAS_DEC_LAYERS];
        assert_ptr_equal(l->W, m->params + off);
        off += (size_t)l->in * l->out;
        assert_ptr_equal(l->b, m->params + off);
        off += (size_t)l->out;
    }
    assert_int_equal(off, m->nparams);
    assert_ptr_equal(m->gdec[1].l[3].b + 3, m->grads + m->nparams);
    /* decoder widths with PyTorch's integer division */
    int in, out;
    tcb_atlas_decoder_dims(1024, 1, &in, &out);
    assert_true(in == 1026 && out == 513);
    tcb_atlas_decoder_dims(1024, 2, &in, &out);
    assert_true(in == 513 && out == 256);
    tcb_atlas_model_free(m);
}

static void test_init(void **state)
{
    (void)state;
    tcb_atlas_model *m = make_model(64, 1, 1), *same = make_model(64, 1, 1);
    tcb_atlas_model *other = make_model(64, 1, 2);
    assert_memory_equal(m->params, same->params, m->nparams * sizeof(float));
    assert_memory_not_equal(m->params, other->params, m->nparams * sizeof(float));
    const tcb_linear *ls[] = {&m->enc.l[0], &m->enc.l[2], &m->enc.l[4], &m->dec[0].l[0],
                                    &m->dec[0].l[3]};
    for (size_t t = 0; t < sizeof ls / sizeof *ls; t++) {
        const tcb_linear *l = ls[t];
        double bound = 1.0 / sqrt(l->in), mx = 0.0, sum = 0.0;
        size_t n = (size_t)l->in * l->out;
        for (size_t i = 0; i < n; i++) {
            mx = fmax(mx, fabs(l->W[i]));
            sum += l->W[i];
        }
        for (int i = 0; i < l->out; i++) assert_true(fabs(l->b[i]) <= bound);
        assert_true(mx <= bound && mx > 0.9 * bound); /* the whole range is used */
        assert_true(fabs(sum / n) < 0.1 * bound);     /* centred */
    }
    tcb_atlas_model_free(m), tcb_atlas_model_free(same), tcb_atlas_model_free(other);
}

typedef struct {
    tcb_atlas_model *m;
    tcb_atlas_work *w;
    float clouds[B * N * 3], uv[M * 2], g[3][B * M * 3];
    float out[3][B * M * 3];
} fixture;

static void fixture_make(fixture *f)
{
    tcb_error err = {0};
    f->m = make_model(C, P, 3);
    assert_int_equal(tcb_atlas_work_create(f->m, B, N, M, &f->w, &err), TCB_OK);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 3, "test/atlas/inputs");
    tu_fill_uniform(&rng, f->clouds, B * N * 3, -0.5, 0.5);
    tu_fill_uniform(&rng, f->uv, M * 2, 0, 1);
    for (int k = 0; k < 3; k++) tu_fill_uniform(&rng, f->g[k], B * M * 3, -1, 1);
}

static void fixture_free(fixture *f)
{
    tcb_atlas_work_free(f->w);
    tcb_atlas_model_free(f->m);
}

static void step(fixture *f, int tangents, float *grads)
{
    tcb_error err = {0};
    tcb_atlas_model_forward(f->m, f->w, f->clouds, f->uv, f->out[0], tangents ? f->out[1] : NULL,
                            tangents ? f->out[2] : NULL);
    tcb_atlas_model_zero_grad(f->m);
    assert_int_equal(tcb_atlas_model_backward(f->m, f->w, f->g[0], tangents ? f->g[1] : NULL,
                                              tangents ? f->g[2] : NULL, &err),
                     TCB_OK);
    memcpy(grads, f->m->grads, f->m->nparams * sizeof(float));
}

/* Same bits on a repeat with the same thread count. With one thread instead
 * of two only the last bits may move: OpenBLAS's threaded GEMMs (the
 * encoder's) tile their edges differently by thread count. */
static void test_deterministic(void **state)
{
    (void)state;
    int threads = omp_get_max_threads();
    omp_set_num_threads(2);
    fixture f;
    fixture_make(&f);
    assert_int_equal(f.w->nthreads, 2);
    float *g1 = malloc(f.m->nparams * sizeof(float)), *g2 = malloc(f.m->nparams * sizeof(float));
    float out1[3][B * M * 3];
    step(&f, 1, g1);
    memcpy(out1, f.out, sizeof out1);
    step(&f, 1, g2);
    assert_memory_equal(out1, f.out, sizeof out1);
    assert_memory_equal(g1, g2, f.m->nparams * sizeof(float));
    fixture_free(&f);

    omp_set_num_threads(1);
    fixture_make(&f);
    assert_int_equal(f.w->nthreads, 1);
    step(&f, 1, g2);
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < B * M * 3; i++) assert_near(f.out[k][i], out1[k][i], 1e-5);
    double gmax = 0.0;
    for (size_t i = 0; i < f.m->nparams; i++) gmax = fmax(gmax, fabs(g1[i]));
    for (size_t i = 0; i < f.m->nparams; i++) assert_near(g2[i], g1[i], 1e-4 * gmax);
    omp_set_num_threads(threads);
    free(g1), free(g2);
    fixture_free(&f);
}

/* Without tangents φ is the same function and the value-only backward is
 * the full backward with zero tangent gradients. */
static void test_tangent_free(void **state)
{
    (void)state;
    fixture f;
    fixture_make(&f);
    size_t n = f.m->nparams;
    float *full = malloc(n * sizeof(float)), *lean = malloc(n * sizeof(float));
    float phi[B * M * 3];
    memset(f.g[1], 0, sizeof f.g[1]);
    memset(f.g[2], 0, sizeof f.g[2]);
    step(&f, 1, full);
    memcpy(phi, f.out[0], sizeof phi);
    step(&f, 0, lean);
    for (int i = 0; i < B * M * 3; i++) assert_near(f.out[0][i], phi[i], 1e-6 * (1 + fabs(phi[i])));
    double gmax = 0.0;
    for (size_t i = 0; i < n; i++) gmax = fmax(gmax, fabs(full[i]));
    for (size_t i = 0; i < n; i++) assert_near(lean[i], full[i], 1e-5 * gmax);

    /* tangent gradients after a forward without tangents: refused */
    tcb_error err = {0};
    tcb_atlas_model_forward(f.m, f.w, f.clouds, f.uv, f.out[0], NULL, NULL);
    assert_int_equal(tcb_atlas_model_backward(f.m, f.w, f.g[0], f.g[1], NULL, &err),
                     TCB_ERR_INTERNAL);
    assert_non_null(strstr(err.msg, "tangent"));
    free(full), free(lean);
    fixture_free(&f);
}

static void test_work_dims(void **state)
{
    (void)state;
    tcb_atlas_model *m = make_model(C, 3, 1);
    tcb_atlas_work *w = NULL;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_work_create(m, B, N, 10, &w, &err), TCB_ERR_INPUT);
    assert_null(w);
    assert_non_null(strstr(err.msg, "multiple of P=3"));
    tcb_atlas_model *bad;
    assert_int_equal(tcb_atlas_model_create(2, 1, &bad, &err), TCB_ERR_INPUT);
    tcb_atlas_model_free(m);
}

static void test_export_import(void **state)
{
    const char *dir = *state;
    char bin[512], json[512];
    snprintf(bin, sizeof bin, "%s/w.bin", dir);
    snprintf(json, sizeof json, "%s/w.json", dir);
    tcb_error err = {0};
    tcb_atlas_model *m = make_model(C, P, 5), *back = make_model(C, P, 6);
    assert_int_equal(tcb_atlas_model_export(m, bin, json, &err), TCB_OK);
    assert_int_equal(tcb_atlas_model_import(back, bin, json, &err), TCB_OK);
    assert_memory_equal(m->params, back->params, m->nparams * sizeof(float));

    /* the file is little-endian float32 in the flat order */
    FILE *fp = fopen(bin, "rb");
    unsigned char b4[4];
    assert_non_null(fp);
    assert_int_equal(fread(b4, 1, 4, fp), 4);
    fclose(fp);
    uint32_t u = (uint32_t)b4[0] | (uint32_t)b4[1] << 8 | (uint32_t)b4[2] << 16 |
                 (uint32_t)b4[3] << 24;
    float first;
    memcpy(&first, &u, 4);
    assert_true(first == m->params[0]);

    /* the manifest names the tensors as PyTorch's state_dict */
    cJSON *man;
    assert_int_equal(tcb_json_load(json, &man, &err), TCB_OK);
    const cJSON *tensors = cJSON_GetObjectItem(man, "tensors");
    assert_int_equal(cJSON_GetArraySize(tensors), 2 * (TCB_ATLAS_ENC_LAYERS + P * TCB_ATLAS_DEC_LAYERS));
    const cJSON *t = cJSON_GetArrayItem(tensors, 10); /* decoder 0, fc1 weight */
    assert_string_equal(cJSON_GetObjectItem(t, "name")->valuestring, "decoders.0.fc1.weight");
    assert_int_equal(cJSON_GetArrayItem(cJSON_GetObjectItem(t, "shape"), 1)->valueint, C + 2);
    assert_int_equal((size_t)cJSON_GetObjectItem(t, "offset")->valuedouble,
                     (size_t)(m->dec[0].l[0].W - m->params));
    cJSON_Delete(man);

    /* another architecture: refused, naming the manifest and the key */
    tcb_atlas_model *wide = make_model(C, P + 1, 7);
    assert_int_equal(tcb_atlas_model_import(wide, bin, json, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "w.json"));
    assert_non_null(strstr(err.msg, ".P"));
    /* a truncated weight file */
    char *data;
    size_t len;
    assert_int_equal(tcb_read_file(bin, &data, &len, &err), TCB_OK);
    assert_int_equal(tcb_write_file_atomic(bin, data, len - 4, &err), TCB_OK);
    free(data);
    assert_int_equal(tcb_atlas_model_import(back, bin, json, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "w.bin"));
    /* a missing file */
    snprintf(bin, sizeof bin, "%s/missing.bin", dir);
    assert_int_equal(tcb_atlas_model_import(back, bin, json, &err), TCB_ERR_IO);
    tcb_atlas_model_free(m), tcb_atlas_model_free(back), tcb_atlas_model_free(wide);
}

/* The polynomial exp/log1p behind softplus and σ against libm in double,
 * over the whole range the network meets, both sides of the threshold. */
static void test_softplus_accuracy(void **state)
{
    (void)state;
    double worst_sp = 0.0, worst_sig = 0.0, worst_curv = 0.0;
    for (double s = -100.0; s <= 40.0; s += 1.0 / 1024) {
        float sig, curv;
        float sp = tcb_softplus((float)s, &sig);
        float sig2 = tcb_sigmoid((float)s, &curv);
        double x = (float)s;
        double sp_ref = x > 20.0 ? x : log1p(exp(x));
        double sig_ref = x > 20.0 ? 1.0 : 1.0 / (1.0 + exp(-x));
        double curv_ref = x > 20.0 ? 0.0 : sig_ref * (1.0 - sig_ref);
        assert_true(sig == sig2);
        if (sp_ref > 1e-37) worst_sp = fmax(worst_sp, fabs(sp - sp_ref) / sp_ref);
        if (sig_ref > 1e-37) worst_sig = fmax(worst_sig, fabs(sig - sig_ref) / sig_ref);
        if (curv_ref > 1e-37) worst_curv = fmax(worst_curv, fabs(curv - curv_ref) / curv_ref);
    }
    if (worst_sp > 4e-7 || worst_sig > 4e-7 || worst_curv > 8e-7)
        fail_msg("relative errors: softplus %.3g, sigma %.3g, curvature %.3g", worst_sp,
                 worst_sig, worst_curv);
    float sig;
    assert_true(isnan(tcb_softplus(NAN, &sig)));
    assert_true(tcb_softplus(-1000.0f, &sig) >= 0.0f && sig >= 0.0f && sig < 1e-30f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_param_count),
        cmocka_unit_test(test_init),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_tangent_free),
        cmocka_unit_test(test_work_dims),
        cmocka_unit_test_setup_teardown(test_export_import, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_softplus_accuracy),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

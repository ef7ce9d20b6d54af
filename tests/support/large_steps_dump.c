/* Test helper (not installed): the Large-Steps system of a synthetic
 * shape's first frame, applied and solved, with what an independent
 * reference needs to redo both:
 *     large_steps_dump SYNTH_NAME LAMBDA SEED OUT_DIR
 * Writes to OUT_DIR, little-endian:
 *     faces.bin  int32   [nf][3]  the triangles
 *     v.bin      float32 [nv][3]  random vertices (uniform in [−1, 1])
 *     u.bin      float32 [nv][3]  M v (tcb_large_steps_apply)
 *     b.bin      float32 [nv][3]  a random right-hand side
 *     x.bin      float32 [nv][3]  M⁻¹ b (tcb_large_steps_solve)
 *     meta.json  {"nv", "nf", "ne", "lambda"}
 * (tests/integration/test_large_steps_scipy.sh compares them with scipy). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/json.h"
#include "tcb/large_steps.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"
#include "tcb/synth.h"
#include "write_bin.h"

static int write_meta(const char *dir, const tcb_large_steps *ls, int nf, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "nv", ls->nv);
    cJSON_AddNumberToObject(o, "nf", nf);
    cJSON_AddNumberToObject(o, "ne", ls->ne);
    cJSON_AddNumberToObject(o, "lambda", ls->lambda);
    int rc = tcb_path_join(path, sizeof path, err, "%s/meta.json", dir);
    if (!rc) rc = tcb_json_save(path, o, err);
    cJSON_Delete(o);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc != 5) {
        fprintf(stderr, "usage: large_steps_dump SYNTH_NAME LAMBDA SEED OUT_DIR\n");
        return 2;
    }
    tcb_error err = {0};
    tcb_sequence seq;
    tcb_large_steps ls;
    memset(&ls, 0, sizeof ls);
    const char *dir = argv[4];
    int rc = tcb_synth_generate(argv[1], 0, 1, &seq, &err);
    if (rc) {
        fprintf(stderr, "large_steps_dump: %s\n", err.msg);
        return 1;
    }
    rc = tcb_large_steps_init(&ls, seq.n_verts, seq.faces, seq.n_faces, atof(argv[2]), &err);
    size_t n3 = 3 * (size_t)seq.n_verts;
    float *v = malloc(n3 * sizeof *v), *u = malloc(n3 * sizeof *u), *b = malloc(n3 * sizeof *b),
          *x = malloc(n3 * sizeof *x);
    if (!rc && (!v || !u || !b || !x)) rc = tcb_fail(&err, TCB_ERR_NOMEM, "out of memory");
    if (!rc) {
        tcb_rng rng;
        tcb_rng_seed(&rng, (uint64_t)atoll(argv[3]));
        for (size_t i = 0; i < n3; i++) v[i] = (float)(2.0 * tcb_rng_uniform(&rng) - 1.0);
        for (size_t i = 0; i < n3; i++) b[i] = (float)(2.0 * tcb_rng_uniform(&rng) - 1.0);
        tcb_large_steps_apply(&ls, v, u);
        rc = tcb_large_steps_solve(&ls, b, x, &err);
    }
    if (!rc) rc = tcb_test_write_bin(dir, "faces.bin", seq.faces, 3 * (size_t)seq.n_faces * sizeof(int32_t), &err);
    if (!rc) rc = tcb_test_write_bin(dir, "v.bin", v, n3 * sizeof *v, &err);
    if (!rc) rc = tcb_test_write_bin(dir, "u.bin", u, n3 * sizeof *u, &err);
    if (!rc) rc = tcb_test_write_bin(dir, "b.bin", b, n3 * sizeof *b, &err);
    if (!rc) rc = tcb_test_write_bin(dir, "x.bin", x, n3 * sizeof *x, &err);
    if (!rc) rc = write_meta(dir, &ls, seq.n_faces, &err);
    free(v), free(u), free(b), free(x);
    tcb_large_steps_free(&ls);
    tcb_sequence_free(&seq);
    if (rc) fprintf(stderr, "large_steps_dump: %s\n", err.msg);
    return rc ? 1 : 0;
}

/* Test helper (not installed): one paired bootstrap with everything an
 * independent reference needs to redo it:
 *     bootstrap_dump S_A S_B P SEED RESAMPLES OUT_DIR
 * The inputs are synthetic (per-pair levels shared by both methods, A
 * offset by 0.25, per-seed noise: a paired problem with training variance),
 * from a fixed stream. Writes to OUT_DIR, little-endian:
 *     xa.bin      float64 [S_A][P]
 *     xb.bin      float64 [S_B][P]
 *     draws.bin   int32   [RESAMPLES][S_A + S_B + P]  in the draw order
 *     result.txt  "estimate lo hi resamples", %.17g
 * (tests/integration/test_bootstrap_numpy.sh compares them with numpy).
 *     bootstrap_dump S_A S_B P SEED RESAMPLES OUT_DIR LABEL IN_DIR
 * takes xa.bin and xb.bin from IN_DIR instead (a comparison's per-pair
 * values, tests/integration/test_compare.sh) and draws from the stream
 * LABEL ("compare/sl2"), as tcb_compare_cells does. */
#include <stdio.h>
#include <stdlib.h>

#include "tcb/bootstrap.h"
#include "tcb/rng.h"

static void fill(double *x, int seeds, int pairs, double offset, tcb_rng *rng)
{
    for (int s = 0; s < seeds; s++)
        for (int p = 0; p < pairs; p++)
            x[(size_t)s * pairs + p] = (double)(p % 11) + offset + 0.4 * tcb_rng_normal(rng);
}

static int read_file(const char *dir, const char *name, void *data, size_t bytes)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "rb");
    int ok = f && fread(data, 1, bytes, f) == bytes;
    if (f) fclose(f);
    if (!ok) fprintf(stderr, "bootstrap_dump: %s: cannot read %zu bytes\n", path, bytes);
    return ok ? 0 : 1;
}

static int write_file(const char *dir, const char *name, const void *data, size_t bytes)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(data, 1, bytes, f) == bytes;
    if (f && fclose(f)) ok = 0;
    if (!ok) fprintf(stderr, "bootstrap_dump: %s: cannot write\n", path);
    return ok ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc != 7 && argc != 9) {
        fprintf(stderr, "usage: bootstrap_dump S_A S_B P SEED RESAMPLES OUT_DIR [LABEL IN_DIR]\n");
        return 2;
    }
    int sa = atoi(argv[1]), sb = atoi(argv[2]), pairs = atoi(argv[3]), resamples = atoi(argv[5]);
    uint64_t seed = strtoull(argv[4], NULL, 10);
    if (sa < 1 || sb < 1 || pairs < 1 || resamples < 1) {
        fprintf(stderr, "bootstrap_dump: counts must be positive\n");
        return 2;
    }
    size_t per = (size_t)sa + (size_t)sb + (size_t)pairs;
    double *xa = malloc(sizeof *xa * (size_t)sa * pairs), *xb = malloc(sizeof *xb * (size_t)sb * pairs);
    int32_t *draws = malloc(sizeof *draws * per * (size_t)resamples);
    if (!xa || !xb || !draws) return 1;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "bootstrap_dump/inputs");
    fill(xa, sa, pairs, 0.25, &rng);
    fill(xb, sb, pairs, 0.0, &rng);
    if (argc == 9 && (read_file(argv[8], "xa.bin", xa, sizeof *xa * (size_t)sa * pairs) ||
                      read_file(argv[8], "xb.bin", xb, sizeof *xb * (size_t)sb * pairs)))
        return 1;
    tcb_boot_result r;
    tcb_error err = {0};
    int rc = tcb_bootstrap_paired(xa, sa, xb, sb, pairs, seed, argc == 9 ? argv[7] : "bootstrap_dump", resamples,
                                  draws, &r, &err);
    if (rc) fprintf(stderr, "bootstrap_dump: %s\n", err.msg);
    char text[256];
    int len = rc ? 0 : snprintf(text, sizeof text, "%.17g %.17g %.17g %d\n", r.estimate, r.lo, r.hi, r.resamples);
    if (!rc)
        rc = write_file(argv[6], "xa.bin", xa, sizeof *xa * (size_t)sa * pairs) ||
             write_file(argv[6], "xb.bin", xb, sizeof *xb * (size_t)sb * pairs) ||
             write_file(argv[6], "draws.bin", draws, sizeof *draws * per * (size_t)resamples) ||
             write_file(argv[6], "result.txt", text, (size_t)len);
    free(xa);
    free(xb);
    free(draws);
    return rc ? 1 : 0;
}

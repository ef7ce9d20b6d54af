/* The atlas family's training checkpoint (neural/train_ckpt.c through
 * methods/atlas/train_ckpt.c), read into a live trainer. The file ends
 * with an FNV-1a checksum that random bytes never match, which would stop
 * the search at the first check; so the target writes every input with
 * its checksum recomputed, and the checks behind it (settings, lengths,
 * progress) are what is fuzzed. The checksum test itself is a unit test
 * (tests/unit/test_atlas_ckpt.c). A refused file leaves the trainer as it
 * was, as the header promises. */
#include <stdlib.h>
#include <string.h>

#include "fuzz/fuzz_util.h"
#include "fuzz/tiny.h"
#include "methods/atlas/train_ckpt.h"

static tcb_sequence seq;
static tcb_atlas_model *model;
static tcb_atlas_trainer *trainer;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    fuzz_tiny_sequence(&seq);
    fuzz_tiny_trainer(&seq, &model, &trainer);
    return 0;
}

/* The format's checksum (neural/train_ckpt.c): FNV-1a 64 of every byte
 * before the last eight. */
static uint64_t checksum(const uint8_t *p, size_t len)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    for (size_t k = 0; k < len; k++) h = (h ^ p[k]) * 0x100000001b3ULL;
    return h;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t *file = malloc(size + 1);
    fuzz_require(file != NULL, "memory");
    memcpy(file, data, size);
    if (size >= 8) {
        uint64_t h = checksum(file, size - 8);
        memcpy(file + size - 8, &h, 8);
    }
    const char *path = fuzz_file("train.ckpt", file, size);
    free(file);

    size_t bytes = model->nparams * sizeof(float);
    float *before = malloc(bytes ? bytes : 1);
    fuzz_require(before != NULL, "memory");
    memcpy(before, model->params, bytes);
    long long it = trainer->it;
    double seconds = -1;
    tcb_error err = {0};
    int rc = tcb_atlas_train_ckpt_load(trainer, &seq, FUZZ_TINY_SEED, path, &seconds, &err);
    fuzz_check_answer(rc, &err, path);
    if (rc) {
        fuzz_require(!memcmp(before, model->params, bytes) && trainer->it == it && seconds == -1,
                     "a refused checkpoint leaves the trainer as it was");
    } else {
        fuzz_require(trainer->it >= 0 && trainer->it <= trainer->cfg.iterations, "iteration in range");
        fuzz_require(seconds >= 0, "a duration");
    }
    free(before);
    return 0;
}

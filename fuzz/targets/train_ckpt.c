/* The atlas family's training checkpoint (neural/train_ckpt.c through
 * methods/atlas/train_ckpt.c), read into a live trainer, every input with
 * its checksum recomputed (fuzz_file_checksummed): the checks behind it
 * (settings, the sequence's fingerprint, lengths, progress) are what is
 * searched. A refused file leaves the trainer as it was, as the header
 * promises. */
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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file_checksummed("train.ckpt", data, size);

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

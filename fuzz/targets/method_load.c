/* A method's saved fitted model, read by its `load` (the harness resumes a
 * cell's evaluation from it): compiled once per method, FUZZ_METHOD naming
 * it — "mca" (the atlas family's model file, neural/weights.c), "cc" (the
 * same container, another manifest) or "nricp" (its maps,
 * methods/nricp/checkpoint.c, which end with a checksum: FUZZ_CHECKSUMMED
 * has the target recompute it, see fuzz_file_checksummed). The record the
 * harness checks before a load (harness/model_record.c) is not involved:
 * this is what a load does with whatever passed it. */
#include "fuzz/fuzz_util.h"
#include "fuzz/tiny.h"
#include "tcb/registry.h"

#ifndef FUZZ_METHOD
#error "FUZZ_METHOD names the method whose load is fuzzed"
#endif

static tcb_sequence seq;
static const tcb_method_ops *ops;
static void *self;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    fuzz_tiny_sequence(&seq);
    ops = tcb_registry_find(FUZZ_METHOD);
    self = fuzz_tiny_method(FUZZ_METHOD);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
#ifdef FUZZ_CHECKSUMMED
    const char *path = fuzz_file_checksummed("model.bin", data, size);
#else
    const char *path = fuzz_file("model.bin", data, size);
#endif
    tcb_error err = {0};
    fuzz_check_answer(ops->load(self, &seq, path, &err), &err, path);
    return 0;
}

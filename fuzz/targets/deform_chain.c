/* A finished propagate_deform chain (methods/nricp/deform_store.c), read
 * back when an evaluation resumes, every input with its checksum
 * recomputed (fuzz_file_checksummed) so that the checks behind it (the
 * chain's header, target order, lengths, finite points, the targets the
 * chain needs) are what is searched. The chain asked for is the seed's:
 * frame 0 forward to frames 1 and 3. An accepted file fills exactly the
 * chain's clouds, all finite. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz/fuzz_util.h"
#include "fuzz/tiny.h"
#include "methods/nricp/nricp_internal.h"
#include "tcb/geometry.h"

static tcb_sequence seq;
static nricp_method *deform;
static int targets[] = {FUZZ_DEFORM_NEAR, FUZZ_DEFORM_FAR};
static nricp_chain chain = {0, 1, 2, targets, NULL};

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    fuzz_tiny_sequence(&seq);
    deform = fuzz_tiny_deform(&seq);
    chain.outs = malloc(2 * (size_t)seq.n_verts * 3 * sizeof *chain.outs);
    fuzz_require(chain.outs != NULL, "memory");
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file_checksummed("chain.bin", data, size);
    size_t n = 2 * (size_t)seq.n_verts * 3;
    for (size_t x = 0; x < n; x++) chain.outs[x] = NAN;
    tcb_error err = {0};
    int rc = nricp_chain_read(deform, &chain, path, &err);
    fuzz_check_answer(rc, &err, path);
    if (!rc) fuzz_require(tcb_all_finite(chain.outs, n), "an accepted chain fills its clouds with finite points");
    return 0;
}

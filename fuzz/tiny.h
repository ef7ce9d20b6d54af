/* The small objects the checkpoint targets read files against, shared with
 * make_seeds.c so that the seeds it writes are files these objects accept:
 * one short synthetic sequence, each method's tiny settings, and an mca
 * trainer. Every function aborts on failure (a harness error is never a
 * finding). */
#ifndef TCB_FUZZ_TINY_H
#define TCB_FUZZ_TINY_H

#include "methods/atlas/model.h"
#include "methods/atlas/train.h"
#include "tcb/sequence.h"

struct nricp_method;

#define FUZZ_TINY_SEED 5

/* humanoid_jacks, 5 frames, normalized, pools of 500, inputs of 200. */
void fuzz_tiny_sequence(tcb_sequence *out);

/* The params JSON of method "mca", "cc" or "nricp" at its smallest. */
const char *fuzz_tiny_params(const char *method);

/* A created instance of the method with those params. */
void *fuzz_tiny_method(const char *method);

/* The deform chain seed's pairs: frame 0 forward to these two frames. */
#define FUZZ_DEFORM_NEAR 1
#define FUZZ_DEFORM_FAR 3

/* nricp propagate_deform (2 rounds) fitted on seq. */
struct nricp_method *fuzz_tiny_deform(const tcb_sequence *seq);

/* An mca trainer (latent 32, 4 patches, 200 UV samples, 24 iterations) on
 * seq, its model initialised from FUZZ_TINY_SEED. */
void fuzz_tiny_trainer(const tcb_sequence *seq, tcb_atlas_model **model, tcb_atlas_trainer **trainer);

#endif

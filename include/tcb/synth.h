/* tcbench — embedded synthetic sequences (no download needed).
 *
 * Procedurally animated closed meshes of constant topology, near-isometric
 * articulated motion by linear-blend skinning, left/right-symmetric limbs,
 * deterministic from a seed. */
#ifndef TCB_SYNTH_H
#define TCB_SYNTH_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/sequence.h"

#ifdef __cplusplus
extern "C" {
#endif

int tcb_synth_count(void);
const char *tcb_synth_name(int k);
const char *tcb_synth_description(int k);

/* Raw (un-normalized) frames of the named sequence; n_frames ≤ 0 → the
 * sequence's default length (≥ 30). The seed varies the motion phase and
 * shape proportions slightly, never the topology. */
int tcb_synth_generate(const char *name, uint64_t seed, int n_frames, tcb_sequence *out,
                       tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif

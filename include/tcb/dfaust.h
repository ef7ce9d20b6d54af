/* tcbench — DFAUST registrations (Bogo et al. 2017) as a tcb_sequence.
 *
 * <root>/registrations_m.hdf5 and <root>/registrations_f.hdf5 (either may be
 * absent; each subject is in the one of its gender) hold one float dataset
 * per "<subject>_<sequence>" of shape (V, 3, F) — V = 6890 SMPL vertices,
 * the F frames on the LAST axis — and an integer "faces" (NF, 3) shared by
 * every registration. A DFAUST sequence such as jumping_jacks is every
 * subject that performed it (reference-protocol §1.1), one block of frames
 * per subject (tcb/block.h), frames-major like every other sequence. The
 * coordinates are kept raw (§1.3: no scaling, no centring). */
#ifndef TCB_DFAUST_H
#define TCB_DFAUST_H

#include "tcb/error.h"
#include "tcb/sequence.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_DFAUST_FILE_M "registrations_m.hdf5"
#define TCB_DFAUST_FILE_F "registrations_f.hdf5"

/* The raw frames of `sequence` (also the sequence's name) for subjects[0..n)
 * in that order, or with n == 0 for every subject of either file that has
 * "<subject>_<sequence>", in sorted order. Errors (TCB_ERR_INPUT, naming the
 * file and the dataset): no file in root (TCB_ERR_IO), a file HDF5 cannot
 * open (truncated, corrupt), a listed subject without its dataset (or in both
 * files), no subject at all, a registration not float (V, 3, F ≥ 2) or with
 * another V than the first, a missing or malformed "faces" (integer (NF, 3),
 * ids in [0, V)), different faces in the two files, a non-finite coordinate
 * or an unreadable dataset. */
int tcb_dfaust_read(const char *root, const char *sequence, char *const *subjects, int n_subjects,
                    tcb_sequence *out, tcb_error *err);

/* The frames in all and the vertex count tcb_dfaust_read would return,
 * from the registrations' shapes alone (what a dry run needs); the same
 * errors. */
int tcb_dfaust_probe(const char *root, const char *sequence, char *const *subjects, int n_subjects, int *n_frames,
                     int *n_verts, tcb_error *err);

/* tcb_dfaust_read, then tcb_sequence_prepare with opts (as
 * tcb_sequence_load_objdir: NULL for no normalization, default pools, no
 * cache). With opts->cache_dir, the cache key records the two files' sizes
 * and mtimes, the subject list and the options. */
int tcb_sequence_load_dfaust(const char *root, const char *sequence, char *const *subjects, int n_subjects,
                             const tcb_load_opts *opts, tcb_sequence *out, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif

/* DFAUST registration files in the official layout, written for the tests
 * (unit tests and the integration test's helper, write_dfaust.c): dataset
 * "<subject>_<sequence>" float32 of shape (V, 3, F) — the frames on the LAST
 * axis — and "faces" int32 (NF, 3). Every function aborts on failure. */
#ifndef TCB_DFAUST_FILES_H
#define TCB_DFAUST_FILES_H

#include <hdf5.h>
#include <stdint.h>

#include "tcb/sequence.h"

/* A new (truncated) HDF5 file at path. */
hid_t tu_h5_create(const char *path);
void tu_h5_close(hid_t file);

/* Dataset `name` of the given type (file and memory alike), shape and data. */
void tu_h5_write(hid_t file, const char *name, hid_t type, int rank, const hsize_t *dims, const void *data);

/* All frames of s as "<subject>_<sequence>", (V, 3, F): element [v][c][f]
 * is coordinate c of vertex v in frame f. */
void tu_dfaust_write_subject(hid_t file, const char *subject, const char *sequence, const tcb_sequence *s);

/* s's triangles as "faces" (NF, 3). */
void tu_dfaust_write_faces(hid_t file, const tcb_sequence *s);

/* The synthetic humanoid (humanoid_jacks) of `seed` with n_frames raw frames:
 * a stand-in subject. */
void tu_dfaust_subject_frames(uint64_t seed, int n_frames, tcb_sequence *out);

#endif

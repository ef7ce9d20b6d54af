/* The names the HDF5 targets' programs (h5_program.h) build files from:
 * the ones each reader looks for, and one it does not know. make_seeds.c
 * encodes its seeds with the same indices. */
#ifndef TCB_FUZZ_H5_NAMES_H
#define TCB_FUZZ_H5_NAMES_H

enum {
    CACHE_VERTS, CACHE_FACES, CACHE_AREAS, CACHE_NORM_SHIFT, CACHE_POOLS, CACHE_YAW, CACHE_BLOCKS,
    CACHE_FORMAT_VERSION, CACHE_KEY, CACHE_NAME, CACHE_NORM, CACHE_NORM_SCALE, CACHE_CHECKSUM, CACHE_OTHER,
    CACHE_N_NAMES
};
static const char *const cache_names[CACHE_N_NAMES] = {
    "verts", "faces", "areas", "norm_shift", "pools", "yaw", "blocks",
    "format_version", "key", "name", "norm", "norm_scale", "checksum", "other"};
/* The key the cache target loads with. */
#define CACHE_KEY_TEXT "fuzz-key"

/* Sequence "jumping" of subjects 50002 and 50004 in one registrations
 * file, and a dataset of another sequence. */
enum { DFAUST_FACES, DFAUST_50002, DFAUST_50004, DFAUST_OTHER, DFAUST_N_NAMES };
static const char *const dfaust_names[DFAUST_N_NAMES] = {"faces", "50002_jumping", "50004_jumping",
                                                         "50002_punching"};

#endif

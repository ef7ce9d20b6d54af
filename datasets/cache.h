/* Private to datasets/: loading a sequence through the HDF5 cache
 * (cache.c), shared by the readers of files (objdir.c, dfaust.c). */
#ifndef TCB_DATASETS_CACHE_H
#define TCB_DATASETS_CACHE_H

#include "tcb/error.h"
#include "tcb/sequence.h"

/* Reads the raw (unnormalized, pool-less) frames of sequence `name`. */
typedef int (*tcb_raw_reader)(const void *ctx, const char *name, tcb_sequence *out, tcb_error *err);

/* read(ctx, name) then tcb_sequence_prepare with o (NULL: no normalization,
 * default pools, no cache). With o->cache_dir the result is stored there as
 * <name>-<hash>.h5 and later loads skip reading. The entry's key is the
 * format version, the name (it seeds the pools), the options and `source`:
 * text naming everything the raw frames depend on (files with sizes and
 * mtimes, selections), so a change to any of them reads afresh. */
int tcb_cache_load(const char *name, const tcb_load_opts *o, const char *source, tcb_raw_reader read,
                   const void *ctx, tcb_sequence *out, tcb_error *err);

#endif

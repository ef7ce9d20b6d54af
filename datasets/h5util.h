/* Private to datasets/: HDF5 idioms shared by the sequence cache (cache.c)
 * and the DFAUST reader (dfaust.c). */
#ifndef TCB_DATASETS_H5UTIL_H
#define TCB_DATASETS_H5UTIL_H

#include <hdf5.h>

/* HDF5 prints its error stack by default; library code must not print, so
 * every entry point silences it and restores the caller's handler after. */
typedef struct tcb_h5_quiet {
    H5E_auto2_t func;
    void *data;
} tcb_h5_quiet;

static inline void tcb_h5_quiet_begin(tcb_h5_quiet *q)
{
    H5Eget_auto2(H5E_DEFAULT, &q->func, &q->data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static inline void tcb_h5_quiet_end(const tcb_h5_quiet *q) { H5Eset_auto2(H5E_DEFAULT, q->func, q->data); }

typedef struct tcb_h5_shape {
    int rank;
    hsize_t dims[H5S_MAX_RANK];
    H5T_class_t type_class; /* H5T_FLOAT, H5T_INTEGER, ... */
} tcb_h5_shape;

/* The shape and element class of dataset `name`; −1 when it is absent, not
 * a dataset or unreadable. */
int tcb_h5_shape_of(hid_t file, const char *name, tcb_h5_shape *out);

#endif

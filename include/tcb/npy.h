/* tcbench — reader and writer of NumPy .npy files (the format of numpy.save).
 *
 * The format (numpy.lib.format, versions 1.0, 2.0 and 3.0): the magic
 * "\x93NUMPY", a major and a minor version byte, the header's length
 * (little-endian uint16 in 1.0, uint32 in 2.0 and 3.0), then the header: a
 * Python dict literal such as
 *     {'descr': '<f8', 'fortran_order': False, 'shape': (500, 3), }
 * padded with spaces and ended by '\n' (latin-1 in 1.0/2.0, utf-8 in 3.0),
 * then the elements, nothing else.
 *
 * Read here: the dtypes numpy writes as "[<>|]" + kind + size for bool (b1),
 * signed and unsigned integers (i1 i2 i4 i8, u1 u2 u4 u8) and floats (f2 f4 f8;
 * f2, IEEE half, converts exactly),
 * either byte order, C or Fortran order, any number of dimensions up to
 * TCB_NPY_MAX_DIMS. Refused with a message saying so: structured, object,
 * string, complex and datetime dtypes. The header is parsed strictly
 * (exactly the three keys; a one-element shape needs its comma, as in
 * Python), and the data must be exactly as long as the shape says.
 *
 * tcb_npy_save writes arrays (version 1.0, little-endian, C order).
 *
 * Everything is parsed from a memory buffer, so a fuzzer can drive
 * tcb_npy_parse directly; tcb_npy_load reads a file through it and its
 * errors name the file. */
#ifndef TCB_NPY_H
#define TCB_NPY_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* numpy's own limit (NPY_MAXDIMS) before numpy 2. */
#define TCB_NPY_MAX_DIMS 32

typedef struct tcb_npy {
    int major, minor;             /* format version */
    char descr[8];                /* as written, e.g. "<f8" */
    char kind;                    /* 'b' bool, 'i' signed, 'u' unsigned, 'f' float */
    int item_size;                /* bytes per element: 1, 2, 4 or 8 */
    int big_endian;               /* '>' (one-byte types: 0) */
    int fortran_order;            /* the elements are stored column-major */
    int ndim;                     /* 0 for a scalar */
    uint64_t shape[TCB_NPY_MAX_DIMS];
    uint64_t count;               /* product of shape (1 for a scalar) */
    const unsigned char *data;    /* count * item_size bytes, inside the parsed buffer */
    char *owned;                  /* tcb_npy_load's copy of the file (data points into it) */
} tcb_npy;

/* Parses the buffer buf[0..len) into *out (which then points into buf).
 * Errors (TCB_ERR_INPUT) say what is wrong and where, without a file name:
 * callers prefix one. */
int tcb_npy_parse(const void *buf, size_t len, tcb_npy *out, tcb_error *err);

/* Reads and parses the file at path; errors start with the path. Free
 * with tcb_npy_free. */
int tcb_npy_load(const char *path, tcb_npy *out, tcb_error *err);
void tcb_npy_free(tcb_npy *a);

/* The elements in C (row-major) order, whatever the stored order, as
 * out[0..count). Neither rounds silently:
 *   to_int64: integer and bool arrays; a float array is refused (an id
 *             must not come out of a rounding), and so is a u8 element
 *             beyond INT64_MAX (naming its index).
 *   to_double: float arrays as they are (NaN and infinities included: the
 *             caller judges them); integer and bool arrays when every
 *             element is exactly a double (|x| <= 2^53), else refused
 *             naming the element. */
int tcb_npy_to_int64(const tcb_npy *a, int64_t *out, tcb_error *err);
int tcb_npy_to_double(const tcb_npy *a, double *out, tcb_error *err);

/* "(500, 3)" as numpy prints a shape, into out[size]. */
void tcb_npy_shape_text(const tcb_npy *a, char *out, size_t size);

/* ---- Writing (core/npy_write.c) --------------------------------------- */

/* What the writer takes: elements in the host's representation. */
typedef enum tcb_npy_dtype { TCB_NPY_F4, TCB_NPY_F8, TCB_NPY_I4, TCB_NPY_I8 } tcb_npy_dtype;

/* Writes the C-ordered array data[product of shape] as path, atomically
 * (tcb/fsutil.h: a killed writer leaves no partial file), in the one form
 * every .npy reader takes: format version 1.0, little-endian ('<f4', '<f8',
 * '<i4', '<i8'), C order, the header padded as numpy pads it (the data
 * start at a multiple of 64 bytes), so the file is byte for byte what
 * numpy.save writes for the same array. ndim is 0 (a scalar) to
 * TCB_NPY_MAX_DIMS. Errors name the file. */
int tcb_npy_save(const char *path, tcb_npy_dtype dtype, int ndim, const uint64_t *shape, const void *data,
                 tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif

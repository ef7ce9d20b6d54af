/* Private to core/: the .npy header dict, parsed (core/npy_header.c) for
 * the reader (core/npy.c). */
#ifndef TCB_CORE_NPY_HEADER_H
#define TCB_CORE_NPY_HEADER_H

#include <stddef.h>

#include "tcb/npy.h"

/* Parses the header text[0..len) (the dict and its padding) into out's
 * descr, kind, item_size, big_endian, fortran_order, ndim and shape.
 * Errors start with "header: " and say what is wrong at which byte. */
int tcb_npy_parse_header(const char *text, size_t len, tcb_npy *out, tcb_error *err);

#endif

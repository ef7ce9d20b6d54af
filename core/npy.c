/* The .npy reader (tcb/npy.h): the prefix, the data's length, and the
 * elements converted to what the caller asks for.
 *
 * Elements are decoded byte by byte in the file's byte order, so the code
 * is the same on any host and needs no swapping step; Fortran-ordered
 * arrays are read through an index map into C order. Sizes are checked
 * before they are multiplied, so no shape, however large, overflows. */
#include "tcb/npy.h"

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/npy_header.h"
#include "tcb/fsutil.h"

_Static_assert(sizeof(float) == 4 && sizeof(double) == 8, "f4 and f8 are read as IEEE float and double");

static const unsigned char MAGIC[6] = {0x93, 'N', 'U', 'M', 'P', 'Y'};

/* The header's offset and length, from the magic, the version and the
 * length field (2 bytes in 1.0, 4 in 2.0 and 3.0; little-endian). */
static int parse_prefix(const unsigned char *b, size_t len, tcb_npy *out, size_t *hstart, size_t *hlen,
                        tcb_error *err)
{
    if (len < sizeof MAGIC || memcmp(b, MAGIC, sizeof MAGIC))
        return tcb_fail(err, TCB_ERR_INPUT, "not a .npy file (it does not start with \\x93NUMPY)");
    if (len < 8) return tcb_fail(err, TCB_ERR_INPUT, "truncated: %zu bytes, not even the version", len);
    out->major = b[6], out->minor = b[7];
    if (out->minor != 0 || out->major < 1 || out->major > 3)
        return tcb_fail(err, TCB_ERR_INPUT, "format version %d.%d is not supported (1.0, 2.0 and 3.0 are)",
                        out->major, out->minor);
    size_t field = out->major == 1 ? 2 : 4;
    if (len < 8 + field)
        return tcb_fail(err, TCB_ERR_INPUT, "truncated: %zu bytes, not even the header's length", len);
    *hlen = 0;
    for (size_t k = 0; k < field; k++) *hlen |= (size_t)b[8 + k] << (8 * k);
    *hstart = 8 + field;
    if (*hlen > len - *hstart)
        return tcb_fail(err, TCB_ERR_INPUT, "truncated: the header says it has %zu bytes, the file has %zu after the prefix",
                        *hlen, len - *hstart);
    return TCB_OK;
}

static int too_large(const tcb_npy *a, tcb_error *err)
{
    char shape[256];
    tcb_npy_shape_text(a, shape, sizeof shape);
    return tcb_fail(err, TCB_ERR_INPUT, "shape %s of %s is too large to address", shape, a->descr);
}

/* count = product of shape (0 when a dimension is 0, however large the
 * others), and the data's bytes; every product checked before it is made.
 * (Beyond SIZE_MAX it cannot equal the buffer's length, which the caller
 * compares it with.) */
static int data_size(tcb_npy *a, uint64_t *bytes, tcb_error *err)
{
    a->count = 1;
    for (int d = 0; d < a->ndim; d++)
        if (a->shape[d] == 0) a->count = 0;
    for (int d = 0; d < a->ndim && a->count; d++) {
        if (a->count > UINT64_MAX / a->shape[d]) return too_large(a, err);
        a->count *= a->shape[d];
    }
    if (a->count > UINT64_MAX / (uint64_t)a->item_size) return too_large(a, err);
    *bytes = a->count * (uint64_t)a->item_size;
    return TCB_OK;
}

int tcb_npy_parse(const void *buf, size_t len, tcb_npy *out, tcb_error *err)
{
    const unsigned char *b = buf;
    size_t hstart = 0, hlen = 0;
    uint64_t bytes = 0;
    memset(out, 0, sizeof *out);
    int rc = parse_prefix(b, len, out, &hstart, &hlen, err);
    if (!rc) rc = tcb_npy_parse_header((const char *)b + hstart, hlen, out, err);
    if (!rc) rc = data_size(out, &bytes, err);
    if (rc) return rc;
    size_t have = len - hstart - hlen;
    if (bytes != have) {
        char shape[256];
        tcb_npy_shape_text(out, shape, sizeof shape);
        return tcb_fail(err, TCB_ERR_INPUT, "%s: shape %s of %s needs %" PRIu64 " bytes of data, the file has %zu",
                        bytes > have ? "truncated" : "bytes after the data", shape, out->descr, bytes, have);
    }
    out->data = b + hstart + hlen;
    return TCB_OK;
}

int tcb_npy_load(const char *path, tcb_npy *out, tcb_error *err)
{
    char *buf;
    size_t len;
    memset(out, 0, sizeof *out);
    int rc = tcb_read_file(path, &buf, &len, err);
    if (rc) return rc;
    rc = tcb_npy_parse(buf, len, out, err);
    if (rc) {
        free(buf);
        tcb_error_prefix(err, "%s: ", path);
        return rc;
    }
    out->owned = buf;
    return TCB_OK;
}

void tcb_npy_free(tcb_npy *a)
{
    free(a->owned);
    memset(a, 0, sizeof *a);
}

void tcb_npy_shape_text(const tcb_npy *a, char *out, size_t size)
{
    size_t used = (size_t)snprintf(out, size, "(");
    for (int d = 0; d < a->ndim && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, "%s%" PRIu64, d ? ", " : "", a->shape[d]);
    if (used < size) snprintf(out + used, size - used, "%s)", a->ndim == 1 ? "," : "");
}

/* Where C-order element c is stored: c itself, or its column-major place. */
static uint64_t storage_index(const tcb_npy *a, uint64_t c)
{
    if (!a->fortran_order || a->ndim < 2) return c;
    uint64_t idx[TCB_NPY_MAX_DIMS], at = 0, stride = 1;
    for (int d = a->ndim - 1; d >= 0; d--) idx[d] = c % a->shape[d], c /= a->shape[d];
    for (int d = 0; d < a->ndim; d++) at += idx[d] * stride, stride *= a->shape[d];
    return at;
}

/* C-order element c's bytes as an unsigned number, in the file's byte order. */
static uint64_t element_bits(const tcb_npy *a, uint64_t c)
{
    const unsigned char *p = a->data + storage_index(a, c) * (uint64_t)a->item_size;
    int n = a->item_size;
    uint64_t v = 0;
    for (int k = 0; k < n; k++) v |= (uint64_t)p[a->big_endian ? n - 1 - k : k] << (8 * k);
    return v;
}

/* An integer or bool element; *beyond_int64: a u8 beyond INT64_MAX. */
static int64_t integer_element(const tcb_npy *a, uint64_t c, int *beyond_int64)
{
    uint64_t v = element_bits(a, c);
    *beyond_int64 = a->kind == 'u' && v > (uint64_t)INT64_MAX;
    if (a->kind == 'i' && a->item_size < 8 && v >> (8 * a->item_size - 1)) v |= ~UINT64_C(0) << (8 * a->item_size);
    int64_t s;
    memcpy(&s, &v, sizeof s); /* two's complement: int64_t has no other representation */
    return s;
}

/* IEEE 754 binary16 (numpy's float16: Occupancy Flow's point clouds),
 * exactly: every half is a double. */
static double half_value(uint32_t h)
{
    int sign = h >> 15, exp = (h >> 10) & 0x1f;
    uint32_t mant = h & 0x3ff;
    double v = exp == 0    ? ldexp((double)mant, -24)                        /* zero, subnormal */
               : exp == 31 ? (mant ? NAN : INFINITY)
                           : ldexp((double)(mant | 0x400), exp - 25);     /* 1.mant × 2^(exp-15) */
    return sign ? -v : v;
}

static double float_element(const tcb_npy *a, uint64_t c)
{
    uint64_t v = element_bits(a, c);
    if (a->item_size == 2) return half_value((uint32_t)v);
    if (a->item_size == 8) {
        double d;
        memcpy(&d, &v, sizeof d);
        return d;
    }
    uint32_t v32 = (uint32_t)v;
    float f;
    memcpy(&f, &v32, sizeof f);
    return f;
}

/* A bool element other than 0 or 1 is not a bool numpy wrote. */
static int check_bool(const tcb_npy *a, uint64_t c, int64_t v, tcb_error *err)
{
    if (a->kind != 'b' || v == 0 || v == 1) return TCB_OK;
    return tcb_fail(err, TCB_ERR_INPUT, "element %" PRIu64 ": byte %" PRId64 " is not a bool (0 or 1)", c, v);
}

int tcb_npy_to_int64(const tcb_npy *a, int64_t *out, tcb_error *err)
{
    if (a->kind == 'f')
        return tcb_fail(err, TCB_ERR_INPUT, "dtype %s: expected integers, got floats (they are not rounded to integers)",
                        a->descr);
    for (uint64_t c = 0; c < a->count; c++) {
        int beyond;
        out[c] = integer_element(a, c, &beyond);
        if (beyond)
            return tcb_fail(err, TCB_ERR_INPUT, "element %" PRIu64 ": %" PRIu64 " is beyond the int64 range", c,
                            element_bits(a, c));
        int rc = check_bool(a, c, out[c], err);
        if (rc) return rc;
    }
    return TCB_OK;
}

/* 2^53: the largest range of integers a double holds exactly. */
#define EXACT_INT 9007199254740992LL

int tcb_npy_to_double(const tcb_npy *a, double *out, tcb_error *err)
{
    for (uint64_t c = 0; c < a->count; c++) {
        if (a->kind == 'f') {
            out[c] = float_element(a, c);
            continue;
        }
        int beyond;
        int64_t v = integer_element(a, c, &beyond);
        if (beyond || v > EXACT_INT || v < -EXACT_INT)
            return tcb_fail(err, TCB_ERR_INPUT, "element %" PRIu64 " (dtype %s) is not exactly a double", c, a->descr);
        int rc = check_bool(a, c, v, err);
        if (rc) return rc;
        out[c] = (double)v;
    }
    return TCB_OK;
}

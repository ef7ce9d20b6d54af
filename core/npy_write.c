/* The .npy writer (tcb/npy.h): version 1.0, little-endian, C order.
 *
 * Elements are encoded byte by byte from their bits, as the reader decodes
 * them, so one code path writes the same file on any host (no separate
 * byte-swapping branch that only a big-endian machine would run). The
 * header follows numpy.lib.format exactly, so numpy and tcbench write the
 * same bytes for the same array. */
#include "tcb/npy.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "tcb/fsutil.h"

/* numpy.lib.format.ARRAY_ALIGN: the data start at a multiple of it. */
#define NPY_ALIGN 64
/* Elements encoded per fwrite. */
#define CHUNK_BYTES 65536

static const struct {
    const char *descr;
    int size;
} DTYPES[] = {[TCB_NPY_F4] = {"<f4", 4}, [TCB_NPY_F8] = {"<f8", 8}, [TCB_NPY_I4] = {"<i4", 4},
              [TCB_NPY_I8] = {"<i8", 8}};

/* The magic, the version, the header's length and the header dict padded
 * with spaces and a final '\n' to the alignment, into out; its length.
 * The dict of TCB_NPY_MAX_DIMS 20-digit dimensions fits in 1024 bytes, the
 * whole prefix in PREFIX_MAX, and its length in 1.0's 16-bit field. */
#define PREFIX_MAX 2048
static size_t format_prefix(tcb_npy_dtype dtype, int ndim, const uint64_t *shape, char out[PREFIX_MAX])
{
    char dict[1024];
    size_t n = (size_t)snprintf(dict, sizeof dict, "{'descr': '%s', 'fortran_order': False, 'shape': (",
                                DTYPES[dtype].descr);
    for (int d = 0; d < ndim; d++)
        n += (size_t)snprintf(dict + n, sizeof dict - n, "%s%" PRIu64, d ? ", " : "", shape[d]);
    n += (size_t)snprintf(dict + n, sizeof dict - n, "%s), }", ndim == 1 ? "," : "");
    size_t total = 10 + n + 1; /* prefix, dict, '\n' */
    total += (NPY_ALIGN - total % NPY_ALIGN) % NPY_ALIGN;
    size_t hlen = total - 10;
    memcpy(out, "\x93NUMPY\x01\x00", 8);
    out[8] = (char)(hlen & 0xff), out[9] = (char)(hlen >> 8);
    memcpy(out + 10, dict, n);
    memset(out + 10 + n, ' ', hlen - n - 1);
    out[total - 1] = '\n';
    return total;
}

/* count elements of item_size bytes from src, as little-endian bytes at dst. */
static void encode(const unsigned char *src, size_t count, int item_size, unsigned char *dst)
{
    for (size_t c = 0; c < count; c++, src += item_size, dst += item_size) {
        uint64_t v;
        if (item_size == 8) {
            memcpy(&v, src, 8);
        } else {
            uint32_t v32;
            memcpy(&v32, src, 4);
            v = v32;
        }
        for (int k = 0; k < item_size; k++) dst[k] = (unsigned char)(v >> (8 * k));
    }
}

static int write_data(FILE *fp, const void *data, uint64_t count, int item_size)
{
    unsigned char buf[CHUNK_BYTES];
    size_t per_chunk = sizeof buf / (size_t)item_size;
    const unsigned char *src = data;
    for (uint64_t done = 0; done < count;) {
        size_t n = count - done < per_chunk ? (size_t)(count - done) : per_chunk;
        encode(src + done * (uint64_t)item_size, n, item_size, buf);
        if (fwrite(buf, (size_t)item_size, n, fp) != n) return -1;
        done += n;
    }
    return 0;
}

/* The element count, refused when it cannot be addressed in memory. */
static int element_count(const char *path, int ndim, const uint64_t *shape, int item_size, uint64_t *count,
                         tcb_error *err)
{
    *count = 1;
    for (int d = 0; d < ndim; d++) {
        if (shape[d] && *count > SIZE_MAX / (uint64_t)item_size / shape[d])
            return tcb_fail(err, TCB_ERR_INPUT, "%s: dimension %d of %" PRIu64 " is too large to write", path, d,
                            shape[d]);
        *count *= shape[d];
    }
    return TCB_OK;
}

int tcb_npy_save(const char *path, tcb_npy_dtype dtype, int ndim, const uint64_t *shape, const void *data,
                 tcb_error *err)
{
    if ((unsigned)dtype >= sizeof DTYPES / sizeof DTYPES[0] || ndim < 0 || ndim > TCB_NPY_MAX_DIMS)
        return tcb_fail(err, TCB_ERR_INTERNAL, "%s: no .npy of dtype %d with %d dimensions", path, (int)dtype, ndim);
    int item_size = DTYPES[dtype].size;
    uint64_t count;
    int rc = element_count(path, ndim, shape, item_size, &count, err);
    if (rc) return rc;
    char prefix[PREFIX_MAX];
    size_t plen = format_prefix(dtype, ndim, shape, prefix);
    tcb_atomic_file af;
    rc = tcb_atomic_open(&af, path, err);
    if (rc) return rc;
    if (fwrite(prefix, 1, plen, af.fp) != plen || write_data(af.fp, data, count, item_size))
        return tcb_atomic_fail(&af, err);
    return tcb_atomic_commit(&af, err);
}

/* The .npz reader (tcb/npz.h): a ZIP archive's central directory, then
 * one member at a time, inflated by zlib and parsed by the .npy reader.
 *
 * Every offset and size read from the file is checked against the file's
 * size before it is used: a truncated or hostile archive is an error
 * naming what is wrong, never a read out of bounds. */
#include "tcb/npz.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

/* The ZIP records' signatures and fixed sizes (APPNOTE.TXT 4.3). */
enum {
    SIG_LOCAL = 0x04034b50, SIG_CENTRAL = 0x02014b50, SIG_END = 0x06054b50,
    SIG_END64 = 0x06064b50, SIG_LOCATOR64 = 0x07064b50,
    LOCAL_SIZE = 30, CENTRAL_SIZE = 46, END_SIZE = 22, END64_SIZE = 56, LOCATOR64_SIZE = 20,
    COMMENT_MAX = 65535, ZIP64_EXTRA = 0x0001
};

#define U16_FULL 0xffffu
#define U32_FULL 0xffffffffu
/* A central directory past this is no .npz of predictions. */
#define CENTRAL_MAX (1u << 30)

static unsigned u16(const unsigned char *p) { return (unsigned)p[0] | (unsigned)p[1] << 8; }
static uint32_t u32(const unsigned char *p) { return (uint32_t)u16(p) | (uint32_t)u16(p + 2) << 16; }
static uint64_t u64(const unsigned char *p) { return (uint64_t)u32(p) | (uint64_t)u32(p + 4) << 32; }

/* len bytes at offset, or an error saying the archive ends first. */
static int read_at(const tcb_npz *z, uint64_t offset, void *buf, size_t len, const char *what, tcb_error *err)
{
    if (offset > z->file_size || len > z->file_size - offset)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: truncated ZIP archive (%s at byte %llu past the end)", z->path,
                        what, (unsigned long long)offset);
    if (len && (fseeko(z->f, (off_t)offset, SEEK_SET) || fread(buf, 1, len, z->f) != len))
        return tcb_fail(err, TCB_ERR_IO, "%s: cannot read %s", z->path, what);
    return TCB_OK;
}

/* Where the central directory is and how many entries it has: the end
 * record, found from the end (it may be followed by nothing but its
 * comment), and its ZIP64 twin when a field overflowed. */
typedef struct central_dir {
    uint64_t n, size, offset;
} central_dir;

static int read_end64(const tcb_npz *z, uint64_t end_at, central_dir *cd, tcb_error *err)
{
    unsigned char loc[LOCATOR64_SIZE], rec[END64_SIZE];
    if (end_at < LOCATOR64_SIZE) return tcb_fail(err, TCB_ERR_INPUT, "%s: ZIP64 archive without its locator", z->path);
    int rc = read_at(z, end_at - LOCATOR64_SIZE, loc, sizeof loc, "the ZIP64 locator", err);
    if (!rc && u32(loc) != SIG_LOCATOR64)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: ZIP64 archive without its locator", z->path);
    if (!rc) rc = read_at(z, u64(loc + 8), rec, sizeof rec, "the ZIP64 end record", err);
    if (rc) return rc;
    if (u32(rec) != SIG_END64) return tcb_fail(err, TCB_ERR_INPUT, "%s: bad ZIP64 end record", z->path);
    if (u32(rec + 16) || u32(rec + 20))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: a multi-disk ZIP archive is not read", z->path);
    *cd = (central_dir){u64(rec + 32), u64(rec + 40), u64(rec + 48)};
    return TCB_OK;
}

static int find_central(const tcb_npz *z, central_dir *cd, tcb_error *err)
{
    size_t tail = z->file_size < END_SIZE + COMMENT_MAX ? (size_t)z->file_size : END_SIZE + COMMENT_MAX;
    unsigned char *buf = malloc(tail ? tail : 1);
    if (!buf) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", z->path);
    int rc = read_at(z, z->file_size - tail, buf, tail, "the end record", err);
    long at = (long)tail - END_SIZE;
    while (!rc && at >= 0 && !(u32(buf + at) == SIG_END && (size_t)at + END_SIZE + u16(buf + at + 20) <= tail)) at--;
    if (!rc && at < 0) rc = tcb_fail(err, TCB_ERR_INPUT, "%s: not a ZIP archive (no end record): an .npz is what np.savez writes", z->path);
    if (rc) {
        free(buf);
        return rc;
    }
    const unsigned char *e = buf + at;
    uint64_t end_at = z->file_size - tail + (uint64_t)at;
    *cd = (central_dir){u16(e + 10), u32(e + 12), u32(e + 16)};
    if (u16(e + 4) || u16(e + 6)) rc = tcb_fail(err, TCB_ERR_INPUT, "%s: a multi-disk ZIP archive is not read", z->path);
    else if (cd->n == U16_FULL || cd->size == U32_FULL || cd->offset == U32_FULL) rc = read_end64(z, end_at, cd, err);
    free(buf);
    return rc;
}

/* The ZIP64 extra field replaces, in this order, each 32-bit field that is
 * all ones: the uncompressed size, the compressed size, the header offset. */
static int apply_zip64(const tcb_npz *z, const unsigned char *x, unsigned len, tcb_npz_member *m, tcb_error *err)
{
    uint64_t *fields[3] = {&m->raw_size, &m->size, &m->header_at};
    for (unsigned at = 0; at + 4 <= len;) {
        unsigned id = u16(x + at), n = u16(x + at + 2);
        if (at + 4 + n > len) break;
        const unsigned char *v = x + at + 4, *end = v + n;
        for (int f = 0; id == ZIP64_EXTRA && f < 3; f++) {
            if (*fields[f] != U32_FULL) continue;
            if (v + 8 > end) return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: short ZIP64 field", z->path, m->name);
            *fields[f] = u64(v);
            v += 8;
        }
        at += 4 + n;
    }
    return TCB_OK;
}

/* One central directory entry at buf[*at], into m; *at moves past it. */
static int parse_entry(const tcb_npz *z, const unsigned char *buf, size_t len, size_t *at, tcb_npz_member *m,
                       tcb_error *err)
{
    const unsigned char *e = buf + *at;
    if (len - *at < CENTRAL_SIZE || u32(e) != SIG_CENTRAL)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: bad central directory entry at byte %zu", z->path, *at);
    size_t nlen = u16(e + 28), xlen = u16(e + 30), clen = u16(e + 32);
    if (len - *at - CENTRAL_SIZE < nlen + xlen + clen)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: truncated central directory", z->path);
    m->name = malloc(nlen + 1);
    if (!m->name) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", z->path);
    memcpy(m->name, e + CENTRAL_SIZE, nlen);
    m->name[nlen] = '\0';
    m->method = (int)u16(e + 10);
    m->crc = u32(e + 16);
    m->size = u32(e + 20), m->raw_size = u32(e + 24), m->header_at = u32(e + 42);
    *at += CENTRAL_SIZE + nlen + xlen + clen;
    if (strlen(m->name) != nlen) return tcb_fail(err, TCB_ERR_INPUT, "%s: a member's name holds a NUL byte", z->path);
    if (u16(e + 8) & 1) return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: encrypted members are not read", z->path, m->name);
    if (m->method != 0 && m->method != 8)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: ZIP compression method %d (np.savez stores, np.savez_compressed deflates: 0 or 8)",
                        z->path, m->name, m->method);
    return apply_zip64(z, e + CENTRAL_SIZE + nlen, (unsigned)xlen, m, err);
}

static int read_members(tcb_npz *z, const central_dir *cd, tcb_error *err)
{
    if (cd->size > CENTRAL_MAX || cd->n > cd->size / CENTRAL_SIZE || cd->offset > z->file_size ||
        cd->size > z->file_size - cd->offset)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: central directory of %llu entries in %llu bytes at byte %llu: not in the file",
                        z->path, (unsigned long long)cd->n, (unsigned long long)cd->size,
                        (unsigned long long)cd->offset);
    unsigned char *buf = malloc(cd->size ? (size_t)cd->size : 1);
    z->members = calloc(cd->n ? (size_t)cd->n : 1, sizeof *z->members);
    int rc = !buf || !z->members ? tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", z->path) : TCB_OK;
    if (!rc) rc = read_at(z, cd->offset, buf, (size_t)cd->size, "the central directory", err);
    size_t at = 0;
    for (uint64_t k = 0; !rc && k < cd->n; k++) {
        z->n++;
        rc = parse_entry(z, buf, (size_t)cd->size, &at, &z->members[k], err);
    }
    free(buf);
    return rc;
}

int tcb_npz_open(const char *path, tcb_npz *z, tcb_error *err)
{
    memset(z, 0, sizeof *z);
    z->path = strdup(path);
    if (!z->path) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    z->f = fopen(path, "rb");
    int rc = z->f ? TCB_OK : tcb_fail(err, TCB_ERR_IO, "%s: cannot open", path);
    if (!rc && (fseeko(z->f, 0, SEEK_END) || ftello(z->f) < 0)) rc = tcb_fail(err, TCB_ERR_IO, "%s: cannot read", path);
    if (!rc) z->file_size = (uint64_t)ftello(z->f);
    central_dir cd = {0};
    if (!rc) rc = find_central(z, &cd, err);
    if (!rc) rc = read_members(z, &cd, err);
    if (rc) tcb_npz_close(z);
    return rc;
}

void tcb_npz_close(tcb_npz *z)
{
    for (int k = 0; k < z->n; k++) free(z->members[k].name);
    free(z->members);
    if (z->f) fclose(z->f);
    free(z->path);
    memset(z, 0, sizeof *z);
}

int tcb_npz_find(const tcb_npz *z, const char *name)
{
    for (int k = 0; k < z->n; k++)
        if (!strcmp(z->members[k].name, name)) return k;
    return -1;
}

/* Deflate's largest ratio is 1032:1 (RFC 1951's longest match per
 * 258-byte code): a member claiming more is damaged, and is refused before
 * its claimed size is allocated. */
#define INFLATE_RATIO 1032u

/* zlib counts in uInt: the stream is fed and drained in slices of this. */
#define SLICE ((size_t)1 << 30)

/* Raw deflate (no zlib header, as ZIP stores it) of in[n] into out[raw]. */
static int inflate_all(const unsigned char *in, size_t n, unsigned char *out, size_t raw)
{
    z_stream s;
    memset(&s, 0, sizeof s);
    if (inflateInit2(&s, -MAX_WBITS) != Z_OK) return Z_MEM_ERROR;
    int zrc = Z_OK;
    size_t in_at = 0, out_at = 0;
    while (zrc == Z_OK) {
        if (!s.avail_in && in_at < n) {
            s.next_in = (unsigned char *)in + in_at, s.avail_in = (uInt)(n - in_at < SLICE ? n - in_at : SLICE);
            in_at += s.avail_in;
        }
        if (!s.avail_out && out_at < raw) {
            s.next_out = out + out_at, s.avail_out = (uInt)(raw - out_at < SLICE ? raw - out_at : SLICE);
            out_at += s.avail_out;
        }
        zrc = inflate(&s, Z_NO_FLUSH); /* Z_BUF_ERROR: input or room ran out first */
    }
    int done = zrc == Z_STREAM_END && s.total_out == raw;
    inflateEnd(&s);
    return done ? Z_OK : zrc == Z_MEM_ERROR ? Z_MEM_ERROR : Z_DATA_ERROR;
}

static uint32_t crc_of(const unsigned char *p, size_t n)
{
    uLong c = crc32(0L, Z_NULL, 0);
    for (size_t at = 0; at < n; at += SLICE) c = crc32(c, p + at, (uInt)(n - at < SLICE ? n - at : SLICE));
    return (uint32_t)c;
}

/* The member's .npy bytes into *raw (malloc'ed, m->raw_size long). */
static int member_bytes(const tcb_npz *z, const tcb_npz_member *m, unsigned char **raw, tcb_error *err)
{
    unsigned char h[LOCAL_SIZE];
    int rc = read_at(z, m->header_at, h, sizeof h, "a member's header", err);
    if (rc) return rc;
    if (u32(h) != SIG_LOCAL) return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: bad local header", z->path, m->name);
    uint64_t data_at = m->header_at + LOCAL_SIZE + u16(h + 26) + u16(h + 28);
    if (data_at > z->file_size || m->size > z->file_size - data_at || (m->method == 0 && m->size != m->raw_size) ||
        m->raw_size / INFLATE_RATIO > m->size)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: %llu bytes stored for %llu: a damaged archive", z->path, m->name,
                        (unsigned long long)m->size, (unsigned long long)m->raw_size);
    *raw = malloc(m->raw_size ? (size_t)m->raw_size : 1);
    unsigned char *packed = m->method == 0 ? *raw : malloc(m->size ? (size_t)m->size : 1);
    if (!*raw || !packed) rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: %s: out of memory", z->path, m->name);
    if (!rc) rc = read_at(z, data_at, packed, (size_t)m->size, m->name, err);
    int zrc = rc || m->method == 0 ? Z_OK : inflate_all(packed, (size_t)m->size, *raw, (size_t)m->raw_size);
    if (!rc && zrc != Z_OK)
        rc = tcb_fail(err, zrc == Z_MEM_ERROR ? TCB_ERR_NOMEM : TCB_ERR_INPUT, "%s: %s: cannot inflate (zlib %d)",
                      z->path, m->name, zrc);
    if (!rc && crc_of(*raw, (size_t)m->raw_size) != m->crc)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: %s: CRC-32 mismatch (a damaged archive)", z->path, m->name);
    if (packed != *raw) free(packed);
    if (rc) {
        free(*raw);
        *raw = NULL;
    }
    return rc;
}

int tcb_npz_read(const tcb_npz *z, int k, tcb_npy *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    const tcb_npz_member *m = &z->members[k];
    unsigned char *raw = NULL;
    int rc = member_bytes(z, m, &raw, err);
    if (rc) return rc;
    rc = tcb_npy_parse(raw, (size_t)m->raw_size, out, err);
    if (rc) {
        free(raw);
        tcb_error_prefix(err, "%s: %s: ", z->path, m->name);
        return rc;
    }
    out->owned = (char *)raw;
    return TCB_OK;
}

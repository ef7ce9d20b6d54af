/* HDF5 cache of a loaded sequence, so benchmark runs skip parsing.
 *
 * Layout (one file per sequence and options):
 *   /verts      float32 [F][V][3]     /faces   int32 [NF][3]
 *   /areas      float64 [F]           /norm_shift float64 [F][3]
 *   /pools      float32 [F][P][3]     (absent when P = 0)
 *   /yaw        float64 [F]           (absent when not rotation-aligned)
 *   /blocks     compound {name: string[64], start, n_frames: int32} [B]
 *               (absent for a sequence without blocks)
 *   attributes on /: format_version, key, name, norm, norm_scale, checksum
 *   (FNV-1a 64 of the arrays and the normalization, sequence_checksum).
 * The file is written under a temporary name and renamed into place. HDF5
 * checksums its metadata but not the data, so the checksum is what tells a
 * flipped bit in the vertices from a vertex. */
#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "datasets/cache.h"
#include "datasets/h5util.h"
#include "datasets/strbuf.h"
#include "tcb/fsutil.h"
#include "tcb/geometry.h"
#include "tcb/hash.h"
#include "tcb/sequence.h"

/* Bump when the layout or the meaning of any field changes (4: /blocks,
 * 5: checksum). */
#define CACHE_FORMAT_VERSION 5

/* tcb_block as an HDF5 compound, the same in memory and in the file. */
static hid_t block_type(void)
{
    hid_t str = H5Tcopy(H5T_C_S1), t = H5Tcreate(H5T_COMPOUND, sizeof(tcb_block));
    int bad = str < 0 || t < 0 || H5Tset_size(str, TCB_BLOCK_NAME_MAX) < 0 ||
              H5Tinsert(t, "name", HOFFSET(tcb_block, name), str) < 0 ||
              H5Tinsert(t, "start", HOFFSET(tcb_block, start), H5T_NATIVE_INT) < 0 ||
              H5Tinsert(t, "n_frames", HOFFSET(tcb_block, n_frames), H5T_NATIVE_INT) < 0;
    if (str >= 0) H5Tclose(str);
    if (bad && t >= 0) H5Tclose(t);
    return bad ? -1 : t;
}

/* Every array as loaded, the normalization, and of the blocks what they
 * mean (a name's bytes after its end are not kept by HDF5). */
static uint64_t sequence_checksum(const tcb_sequence *s)
{
    size_t F = (size_t)s->n_frames, nv = F * (size_t)s->n_verts * 3, np = F * (size_t)s->pool_size * 3;
    int norm = (int)s->norm;
    uint64_t h = tcb_fnv1a64(TCB_FNV1A64_OFFSET, &norm, sizeof norm);
    h = tcb_fnv1a64(h, &s->norm_scale, sizeof s->norm_scale);
    h = tcb_fnv1a64(h, s->verts, nv * sizeof *s->verts);
    h = tcb_fnv1a64(h, s->faces, (size_t)s->n_faces * 3 * sizeof *s->faces);
    h = tcb_fnv1a64(h, s->areas, F * sizeof *s->areas);
    h = tcb_fnv1a64(h, s->norm_shift, F * 3 * sizeof *s->norm_shift);
    if (s->pools) h = tcb_fnv1a64(h, s->pools, np * sizeof *s->pools);
    if (s->yaw) h = tcb_fnv1a64(h, s->yaw, F * sizeof *s->yaw);
    for (int k = 0; k < s->n_blocks; k++) {
        const tcb_block *b = &s->blocks[k];
        h = tcb_fnv1a64(h, b->name, strnlen(b->name, sizeof b->name));
        h = tcb_fnv1a64(h, &b->start, sizeof b->start);
        h = tcb_fnv1a64(h, &b->n_frames, sizeof b->n_frames);
    }
    return h;
}

/* ---- writing ---------------------------------------------------------- */

static int write_array(hid_t file, const char *name, hid_t file_type, hid_t mem_type, int rank,
                       const hsize_t *dims, const void *data)
{
    hid_t space = H5Screate_simple(rank, dims, NULL);
    hid_t ds = space < 0 ? -1 : H5Dcreate2(file, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    herr_t st = ds < 0 ? -1 : H5Dwrite(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    if (ds >= 0 && H5Dclose(ds) < 0) st = -1;
    if (space >= 0) H5Sclose(space);
    return st < 0 ? -1 : 0;
}

static int write_attr(hid_t obj, const char *name, hid_t file_type, hid_t mem_type, const void *value)
{
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t a = space < 0 ? -1 : H5Acreate2(obj, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT);
    herr_t st = a < 0 ? -1 : H5Awrite(a, mem_type, value);
    if (a >= 0 && H5Aclose(a) < 0) st = -1;
    if (space >= 0) H5Sclose(space);
    return st < 0 ? -1 : 0;
}

static int write_attr_string(hid_t obj, const char *name, const char *value)
{
    hid_t type = H5Tcopy(H5T_C_S1);
    if (type < 0) return -1;
    int rc = H5Tset_size(type, strlen(value) + 1) < 0 ? -1 : write_attr(obj, name, type, type, value);
    H5Tclose(type);
    return rc;
}

static int write_contents(hid_t file, const tcb_sequence *s, const char *key)
{
    const int version = CACHE_FORMAT_VERSION, norm = (int)s->norm;
    const uint64_t checksum = sequence_checksum(s);
    hsize_t F = (hsize_t)s->n_frames, V = (hsize_t)s->n_verts, P = (hsize_t)s->pool_size;
    hsize_t verts_dims[3] = {F, V, 3}, faces_dims[2] = {(hsize_t)s->n_faces, 3};
    hsize_t shift_dims[2] = {F, 3}, pool_dims[3] = {F, P, 3};
    int bad = write_attr(file, "format_version", H5T_STD_I32LE, H5T_NATIVE_INT, &version) ||
              write_attr_string(file, "key", key) || write_attr_string(file, "name", s->name) ||
              write_attr(file, "norm", H5T_STD_I32LE, H5T_NATIVE_INT, &norm) ||
              write_attr(file, "norm_scale", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &s->norm_scale) ||
              write_attr(file, "checksum", H5T_STD_U64LE, H5T_NATIVE_UINT64, &checksum) ||
              write_array(file, "verts", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, 3, verts_dims, s->verts) ||
              write_array(file, "faces", H5T_STD_I32LE, H5T_NATIVE_INT32, 2, faces_dims, s->faces) ||
              write_array(file, "areas", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, &F, s->areas) ||
              write_array(file, "norm_shift", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, shift_dims, s->norm_shift);
    if (!bad && s->pool_size > 0)
        bad = write_array(file, "pools", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, 3, pool_dims, s->pools);
    if (!bad && s->yaw) bad = write_array(file, "yaw", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, &F, s->yaw);
    if (!bad && s->n_blocks > 0) {
        hsize_t B = (hsize_t)s->n_blocks;
        hid_t type = block_type();
        bad = type < 0 || write_array(file, "blocks", type, type, 1, &B, s->blocks);
        if (type >= 0) H5Tclose(type);
    }
    return bad ? -1 : 0;
}

/* HDF5 does not fsync; a crash must not publish a half-written cache. */
static int fsync_path(const char *path)
{
    int fd = open(path, O_RDONLY);
    if (fd < 0) return -1;
    int rc = fsync(fd);
    close(fd);
    return rc;
}

int tcb_sequence_cache_save(const char *path, const tcb_sequence *s, const char *key, tcb_error *err)
{
    if (!s->areas || !s->norm_shift)
        return tcb_fail(err, TCB_ERR_INTERNAL, "sequence %s: normalize before caching", s->name);
    char tmp[TCB_PATH_MAX];
    int rc = tcb_temp_path_for(path, tmp, sizeof tmp, err);
    if (rc) return rc;
    tcb_h5_quiet q;
    tcb_h5_quiet_begin(&q);
    /* 1.8+ object headers: the key attribute may exceed the 64 KiB limit of
     * the oldest format on long sequences. */
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    hid_t file = fapl < 0 || H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_LATEST) < 0
                     ? -1
                     : H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    int bad = file < 0 || write_contents(file, s, key) != 0;
    if (file >= 0 && H5Fclose(file) < 0) bad = 1;
    if (fapl >= 0) H5Pclose(fapl);
    tcb_h5_quiet_end(&q);
    if (bad || fsync_path(tmp) != 0) {
        unlink(tmp);
        return tcb_fail(err, TCB_ERR_IO, "%s: cannot write sequence cache", path);
    }
    return tcb_publish(tmp, path, err);
}

/* ---- reading ---------------------------------------------------------- */

/* A scalar numeric attribute converted to mem_type. */
static int read_attr(hid_t obj, const char *name, hid_t mem_type, void *out)
{
    if (H5Aexists(obj, name) <= 0) return -1;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0) return -1;
    hid_t space = H5Aget_space(a);
    int ok = space >= 0 && H5Sget_simple_extent_npoints(space) == 1 && H5Aread(a, mem_type, out) >= 0;
    if (space >= 0) H5Sclose(space);
    H5Aclose(a);
    return ok ? 0 : -1;
}

/* A fixed-length string attribute, malloc'ed and NUL-terminated. */
static char *read_attr_string(hid_t obj, const char *name)
{
    if (H5Aexists(obj, name) <= 0) return NULL;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0) return NULL;
    hid_t type = H5Aget_type(a), space = H5Aget_space(a);
    char *buf = NULL;
    if (type >= 0 && space >= 0 && H5Tget_class(type) == H5T_STRING && H5Tis_variable_str(type) == 0 &&
        H5Sget_simple_extent_npoints(space) == 1) {
        size_t size = H5Tget_size(type);
        buf = calloc(size + 1, 1);
        if (buf && H5Aread(a, type, buf) < 0) {
            free(buf);
            buf = NULL;
        }
    }
    if (space >= 0) H5Sclose(space);
    if (type >= 0) H5Tclose(type);
    H5Aclose(a);
    return buf;
}

/* dims[0..rank) of dataset `name`; -1 when absent or of another rank. */
static int array_dims(hid_t file, const char *name, int rank, hsize_t *dims)
{
    tcb_h5_shape sh;
    if (tcb_h5_shape_of(file, name, &sh) != 0 || sh.rank != rank) return -1;
    memcpy(dims, sh.dims, (size_t)rank * sizeof *dims);
    return 0;
}

/* Reads dataset `name` into buf after checking it has exactly `dims`. */
static int read_array(hid_t file, const char *name, hid_t mem_type, int rank, const hsize_t *dims, void *buf)
{
    hsize_t got[3];
    if (array_dims(file, name, rank, got) != 0) return -1;
    for (int d = 0; d < rank; d++)
        if (got[d] != dims[d]) return -1;
    hid_t ds = H5Dopen2(file, name, H5P_DEFAULT);
    if (ds < 0) return -1;
    herr_t st = H5Dread(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
    H5Dclose(ds);
    return st < 0 ? -1 : 0;
}

static int corrupt(const char *path, const char *what, tcb_error *err)
{
    return tcb_fail(err, TCB_ERR_INPUT, "%s: not a valid tcbench sequence cache (%s)", path, what);
}

/* Format version and key, before any large read. */
static int check_key(hid_t file, const char *path, const char *key, tcb_error *err)
{
    int version;
    if (read_attr(file, "format_version", H5T_NATIVE_INT, &version) != 0)
        return corrupt(path, "no format_version", err);
    if (version != CACHE_FORMAT_VERSION)
        return tcb_fail(err, TCB_ERR_UNSUPPORTED, "%s: stale cache (format %d, expected %d)", path, version,
                        CACHE_FORMAT_VERSION);
    char *stored = read_attr_string(file, "key");
    if (!stored) return corrupt(path, "no key", err);
    int same = strcmp(stored, key) == 0;
    free(stored);
    return same ? TCB_OK : tcb_fail(err, TCB_ERR_UNSUPPORTED, "%s: stale cache (source or options changed)", path);
}

/* Sizes from the verts/faces/pools shapes, then allocation of everything. */
static int alloc_from_shapes(hid_t file, const char *path, tcb_sequence *out, tcb_error *err)
{
    hsize_t vd[3], fd[2], pd[3] = {0, 0, 3};
    if (array_dims(file, "verts", 3, vd) != 0 || array_dims(file, "faces", 2, fd) != 0)
        return corrupt(path, "verts or faces missing", err);
    int has_pools = H5Lexists(file, "pools", H5P_DEFAULT) > 0;
    if (has_pools && array_dims(file, "pools", 3, pd) != 0) return corrupt(path, "bad pools", err);
    if (vd[0] > INT32_MAX || vd[1] > INT32_MAX / 3 || vd[2] != 3 || fd[0] > INT32_MAX / 3 || fd[1] != 3 ||
        pd[1] > INT32_MAX / 3 || pd[2] != 3 || (has_pools && (pd[0] != vd[0] || pd[1] == 0)))
        return corrupt(path, "inconsistent array shapes", err);
    char *name = read_attr_string(file, "name");
    if (!name) return corrupt(path, "no name", err);
    int rc = tcb_sequence_alloc(out, name, (int)vd[0], (int)vd[1], (int)fd[0], err);
    free(name);
    if (rc) return rc == TCB_ERR_NOMEM ? rc : corrupt(path, "bad sizes or name", err);
    out->pool_size = (int)pd[1];
    out->areas = malloc((size_t)out->n_frames * sizeof *out->areas);
    out->norm_shift = malloc((size_t)out->n_frames * 3 * sizeof *out->norm_shift);
    out->pools = has_pools ? malloc((size_t)out->n_frames * (size_t)out->pool_size * 3 * sizeof(float)) : NULL;
    int has_yaw = H5Lexists(file, "yaw", H5P_DEFAULT) > 0;
    out->yaw = has_yaw ? malloc((size_t)out->n_frames * sizeof *out->yaw) : NULL;
    if (!out->areas || !out->norm_shift || (has_pools && !out->pools) || (has_yaw && !out->yaw))
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    return TCB_OK;
}

/* The optional /blocks, checked to tile the frames. */
static int read_blocks(hid_t file, const char *path, tcb_sequence *out, tcb_error *err)
{
    if (H5Lexists(file, "blocks", H5P_DEFAULT) <= 0) return TCB_OK;
    hsize_t B;
    if (array_dims(file, "blocks", 1, &B) != 0 || B < 1 || B > (hsize_t)out->n_frames)
        return corrupt(path, "bad blocks", err);
    out->blocks = calloc((size_t)B, sizeof *out->blocks);
    if (!out->blocks) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    out->n_blocks = (int)B;
    hid_t type = block_type();
    int bad = type < 0 || read_array(file, "blocks", type, 1, &B, out->blocks) != 0;
    if (type >= 0) H5Tclose(type);
    if (bad || tcb_blocks_check(out->blocks, out->n_blocks, out->n_frames, "blocks", NULL) != TCB_OK)
        return corrupt(path, "bad blocks", err);
    return TCB_OK;
}

/* What was written was finite (the writer's sequence passed the loaders'
 * checks): a NaN here is a damaged file, and would poison every metric. */
static int all_finite(const tcb_sequence *s)
{
    size_t F = (size_t)s->n_frames;
    return tcb_all_finite(s->verts, F * (size_t)s->n_verts * 3) && tcb_all_finite_d(s->areas, F) &&
           tcb_all_finite_d(s->norm_shift, F * 3) && isfinite(s->norm_scale) &&
           (!s->pools || tcb_all_finite(s->pools, F * (size_t)s->pool_size * 3)) &&
           (!s->yaw || tcb_all_finite_d(s->yaw, F));
}

static int read_contents(hid_t file, const char *path, tcb_sequence *out, tcb_error *err)
{
    int rc = alloc_from_shapes(file, path, out, err);
    if (rc) return rc;
    hsize_t F = (hsize_t)out->n_frames, V = (hsize_t)out->n_verts, P = (hsize_t)out->pool_size;
    hsize_t verts_dims[3] = {F, V, 3}, faces_dims[2] = {(hsize_t)out->n_faces, 3};
    hsize_t shift_dims[2] = {F, 3}, pool_dims[3] = {F, P, 3};
    int norm;
    if (read_attr(file, "norm", H5T_NATIVE_INT, &norm) != 0 ||
        read_attr(file, "norm_scale", H5T_NATIVE_DOUBLE, &out->norm_scale) != 0 ||
        read_array(file, "verts", H5T_NATIVE_FLOAT, 3, verts_dims, out->verts) != 0 ||
        read_array(file, "faces", H5T_NATIVE_INT32, 2, faces_dims, out->faces) != 0 ||
        read_array(file, "areas", H5T_NATIVE_DOUBLE, 1, &F, out->areas) != 0 ||
        read_array(file, "norm_shift", H5T_NATIVE_DOUBLE, 2, shift_dims, out->norm_shift) != 0 ||
        (out->pools && read_array(file, "pools", H5T_NATIVE_FLOAT, 3, pool_dims, out->pools) != 0) ||
        (out->yaw && read_array(file, "yaw", H5T_NATIVE_DOUBLE, 1, &F, out->yaw) != 0))
        return corrupt(path, "unreadable attribute or array", err);
    if (norm < TCB_NORM_NONE || norm > TCB_NORM_PER_FRAME) return corrupt(path, "unknown normalization", err);
    if (!all_finite(out)) return corrupt(path, "a coordinate, area or normalization that is not finite", err);
    out->norm = (tcb_normalization)norm;
    /* Bad ids would turn into out-of-bounds reads far from here. */
    for (size_t i = 0; i < 3 * (size_t)out->n_faces; i++)
        if (out->faces[i] < 0 || out->faces[i] >= out->n_verts) return corrupt(path, "face index out of range", err);
    rc = read_blocks(file, path, out, err);
    uint64_t checksum;
    if (!rc && read_attr(file, "checksum", H5T_NATIVE_UINT64, &checksum) != 0) rc = corrupt(path, "no checksum", err);
    if (!rc && checksum != sequence_checksum(out))
        rc = corrupt(path, "checksum mismatch: the arrays changed after they were saved", err);
    return rc;
}

int tcb_sequence_cache_load(const char *path, const char *key, tcb_sequence *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    out->input_points = TCB_DEFAULT_INPUT_POINTS;
    if (access(path, R_OK) != 0)
        return tcb_fail(err, TCB_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    tcb_h5_quiet q;
    tcb_h5_quiet_begin(&q);
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    int rc = file < 0 ? corrupt(path, "not an HDF5 file", err) : check_key(file, path, key, err);
    if (!rc) rc = read_contents(file, path, out, err);
    if (file >= 0) H5Fclose(file);
    tcb_h5_quiet_end(&q);
    if (rc) tcb_sequence_free(out);
    return rc;
}

/* ---- loading through the cache --------------------------------------- */

/* Everything the cached arrays depend on (cache.h): the format, the name
 * (it seeds the pools), the options and the source. */
static int build_key(const char *name, const tcb_load_opts *o, int pool_size, const char *source,
                     tcb_strbuf *key)
{
    return tcb_sb_printf(key,
                         "tcbench sequence cache v%d\nname=%s\n"
                         "norm=%d pool_size=%d pool_seed=%llu align=%d\n%s",
                         CACHE_FORMAT_VERSION, name, (int)o->norm, pool_size,
                         (unsigned long long)o->pool_seed, o->align_samples, source);
}

static int read_and_prepare(const char *name, const tcb_load_opts *o, tcb_raw_reader read, const void *ctx,
                            tcb_sequence *out, tcb_error *err)
{
    int rc = read(ctx, name, out, err);
    if (!rc) rc = tcb_sequence_prepare(out, o, err);
    if (rc) tcb_sequence_free(out);
    return rc;
}

int tcb_cache_load(const char *name, const tcb_load_opts *opts, const char *source, tcb_raw_reader read,
                   const void *ctx, tcb_sequence *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    static const tcb_load_opts defaults = {TCB_NORM_NONE, TCB_DEFAULT_POOL_SIZE, 0, NULL, 0, NULL};
    const tcb_load_opts *o = opts ? opts : &defaults;
    if (!o->cache_dir || !*o->cache_dir) return read_and_prepare(name, o, read, ctx, out, err);
    tcb_strbuf key = {0};
    if (build_key(name, o, o->pool_size ? o->pool_size : TCB_DEFAULT_POOL_SIZE, source, &key)) {
        free(key.s);
        return tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: out of memory", name);
    }
    char path[TCB_PATH_MAX];
    int rc = tcb_path_join(path, sizeof path, err, "%s/%s-%016llx.h5", o->cache_dir, name,
                           (unsigned long long)tcb_fnv1a64(TCB_FNV1A64_OFFSET, key.s, strlen(key.s)));
    /* A stale, corrupt or unreadable entry is rebuilt, never used, and
     * said: a cache that keeps being rebuilt costs the parse every run. */
    tcb_error ce = {0};
    if (!rc && tcb_is_file(path)) {
        if (tcb_sequence_cache_load(path, key.s, out, &ce) == TCB_OK) {
            free(key.s);
            return TCB_OK;
        }
        tcb_report_log(o->reporter, TCB_LOG_WARN, "sequence cache not reused: %s; reading the sequence again",
                       ce.msg);
    }
    if (!rc) rc = read_and_prepare(name, o, read, ctx, out, err);
    if (!rc && (rc = tcb_sequence_cache_save(path, out, key.s, err))) tcb_sequence_free(out);
    free(key.s);
    return rc;
}

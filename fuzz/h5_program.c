#include "fuzz/h5_program.h"

#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const int type_size[H5P_N_TYPES] = {4, 8, 4, 8, 1, 1, 8};

static hid_t file_type(int type)
{
    switch (type) {
    case H5P_I32: return H5T_STD_I32LE;
    case H5P_I64: return H5T_STD_I64LE;
    case H5P_F32: return H5T_IEEE_F32LE;
    case H5P_F64: return H5T_IEEE_F64LE;
    case H5P_U64: return H5T_STD_U64LE;
    default: return H5T_STD_U8LE;
    }
}

/* Reads the next byte, or 0 past the end. */
typedef struct cursor {
    const uint8_t *p, *end;
} cursor;

static unsigned next(cursor *c) { return c->p < c->end ? *c->p++ : 0; }

/* Copies n bytes into dst, zeros past the end. */
static void take(cursor *c, void *dst, size_t n)
{
    size_t have = (size_t)(c->end - c->p) < n ? (size_t)(c->end - c->p) : n;
    memcpy(dst, c->p, have);
    memset((uint8_t *)dst + have, 0, n - have);
    c->p += have;
}

static void write_object(hid_t file, int attribute, const char *name, hid_t type, hid_t space, const void *data)
{
    if (attribute) {
        hid_t a = H5Acreate2(file, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
        if (a >= 0) H5Awrite(a, type, data), H5Aclose(a);
    } else {
        hid_t d = H5Dcreate2(file, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        if (d >= 0) H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), H5Dclose(d);
    }
}

/* One record; 0 when the program ends here. */
static int record(cursor *c, hid_t file, const char *const *names, int n_names)
{
    if (c->p >= c->end) return 0;
    int attribute = next(c) & 1;
    const char *name = names[next(c) % (unsigned)n_names];
    int type = (int)(next(c) % H5P_N_TYPES), rank = (int)(next(c) % 4);
    if (type == H5P_STR) {
        char text[64];
        int len = (int)(next(c) % 64);
        take(c, text, (size_t)len);
        hid_t str = H5Tcopy(H5T_C_S1), space = H5Screate(H5S_SCALAR);
        H5Tset_size(str, len ? (size_t)len : 1);
        write_object(file, attribute, name, str, space, len ? text : "");
        H5Sclose(space), H5Tclose(str);
        return 1;
    }
    hsize_t dims[3];
    size_t count = 1;
    for (int k = 0; k < rank; k++) dims[k] = next(c) % 64, count *= dims[k];
    if (count > H5P_MAX_ELEMENTS) return 0;
    void *data = malloc(count * (size_t)type_size[type] + 1);
    if (!data) abort();
    take(c, data, count * (size_t)type_size[type]);
    hid_t space = rank ? H5Screate_simple(rank, dims, NULL) : H5Screate(H5S_SCALAR);
    write_object(file, attribute, name, file_type(type), space, data);
    H5Sclose(space);
    free(data);
    return 1;
}

void h5prog_build(const uint8_t *data, size_t size, const char *const *names, int n_names, const char *path)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* refused records are expected: no error stack on stderr */
    hid_t file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0) {
        fprintf(stderr, "h5prog: cannot create %s\n", path);
        abort();
    }
    cursor c = {data, data + size};
    while (record(&c, file, names, n_names)) {}
    H5Fclose(file);
}

static void put(h5prog_buf *b, const void *data, size_t n)
{
    if (b->len + n > b->cap) {
        b->cap = 2 * (b->len + n);
        b->bytes = realloc(b->bytes, b->cap);
        if (!b->bytes) abort();
    }
    memcpy(b->bytes + b->len, data, n);
    b->len += n;
}

static void put_byte(h5prog_buf *b, int v)
{
    uint8_t u = (uint8_t)v;
    put(b, &u, 1);
}

void h5prog_add_array(h5prog_buf *b, int attribute, int name, int type, int rank, const int *dims, const void *data)
{
    put_byte(b, attribute), put_byte(b, name), put_byte(b, type), put_byte(b, rank);
    size_t count = 1;
    for (int k = 0; k < rank; k++) put_byte(b, dims[k]), count *= (size_t)dims[k];
    put(b, data, count * (size_t)type_size[type]);
}

void h5prog_add_string(h5prog_buf *b, int attribute, int name, const char *text)
{
    put_byte(b, attribute), put_byte(b, name), put_byte(b, H5P_STR), put_byte(b, 0);
    put_byte(b, (int)strlen(text)), put(b, text, strlen(text));
}

/* The program type of an HDF5 type, or -1. */
static int program_type(hid_t t)
{
    size_t size = H5Tget_size(t);
    switch (H5Tget_class(t)) {
    case H5T_INTEGER:
        if (size == 1) return H5P_U8;
        if (size == 4) return H5P_I32;
        if (size == 8) return H5Tget_sign(t) == H5T_SGN_NONE ? H5P_U64 : H5P_I64;
        return -1;
    case H5T_FLOAT: return size == 4 ? H5P_F32 : size == 8 ? H5P_F64 : -1;
    case H5T_STRING: return H5P_STR;
    default: return -1;
    }
}

static void from_fail(const char *path, const char *name, const char *why)
{
    fprintf(stderr, "h5prog: %s: %s: %s\n", path, name, why);
    abort();
}

/* One object (attribute: 1) as a record; its type and space are closed here. */
static void add_object(h5prog_buf *b, hid_t obj, int attribute, int name, hid_t type, hid_t space, const char *path,
                       const char *const *names)
{
    int pt = program_type(type), rank = H5Sget_simple_extent_ndims(space);
    hsize_t dims[3] = {0};
    if (pt >= 0 && rank >= 0 && rank <= 3) H5Sget_simple_extent_dims(space, dims, NULL);
    if (pt == H5P_STR) {
        char text[64] = "";
        size_t len = H5Tget_size(type);
        if (H5Tis_variable_str(type) > 0 || len >= sizeof text)
            from_fail(path, names[name], "not a short fixed-length string");
        hid_t mem = H5Tcopy(H5T_C_S1);
        H5Tset_size(mem, len + 1);
        herr_t read = attribute ? H5Aread(obj, mem, text) : H5Dread(obj, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, text);
        H5Tclose(mem);
        if (read < 0) from_fail(path, names[name], "unreadable string");
        h5prog_add_string(b, attribute, name, text);
    } else if (pt >= 0 && rank >= 0 && rank <= 3) {
        int d[3];
        size_t count = 1;
        for (int k = 0; k < rank; k++) {
            if (dims[k] >= 64) from_fail(path, names[name], "a dimension too large for a program");
            d[k] = (int)dims[k], count *= dims[k];
        }
        void *data = malloc(count * (size_t)type_size[pt] + 1);
        if (!data) abort();
        hid_t mem = file_type(pt);
        if ((attribute ? H5Aread(obj, mem, data) : H5Dread(obj, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, data)) < 0)
            from_fail(path, names[name], "unreadable");
        h5prog_add_array(b, attribute, name, pt, rank, d, data);
        free(data);
    }
    H5Tclose(type), H5Sclose(space);
}

void h5prog_from_file(h5prog_buf *b, const char *path, const char *const *names, int n_names)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0) from_fail(path, "", "not an HDF5 file");
    for (int k = 0; k < n_names; k++) {
        if (H5Aexists(file, names[k]) > 0) {
            hid_t a = H5Aopen(file, names[k], H5P_DEFAULT);
            add_object(b, a, 1, k, H5Aget_type(a), H5Aget_space(a), path, names);
            H5Aclose(a);
        } else if (H5Lexists(file, names[k], H5P_DEFAULT) > 0) {
            hid_t d = H5Dopen2(file, names[k], H5P_DEFAULT);
            add_object(b, d, 0, k, H5Dget_type(d), H5Dget_space(d), path, names);
            H5Dclose(d);
        }
    }
    H5Fclose(file);
}

/* Structure-aware fuzzing of the HDF5 readers. Byte-level mutations of an
 * HDF5 file exercise libhdf5's own parser (not ours to fix, and libFuzzer
 * rarely gets past its superblock); what our readers must survive is a
 * well-formed HDF5 file with the wrong contents: missing or extra
 * datasets, other types, ranks and shapes, odd attributes, NaN. So a
 * target reads its input as a small program that builds such a file
 * through the HDF5 API, then hands the file to the reader.
 *
 * The program is a list of records, each
 *   kind   1 byte   even: a dataset, odd: an attribute of the root group
 *   name   1 byte   index into the target's list of names (modulo)
 *   type   1 byte   modulo 7: int32, int64, float32, float64, uint8, string,
 *                   uint64
 *   rank   1 byte   modulo 4 (0: a scalar); a string is always a scalar
 *   dims   rank bytes, each modulo 64
 *   data   the elements, little-endian, count × size bytes; a string:
 *          one length byte (modulo 64) and its characters
 * A record cut short by the end of the input is completed with zeros; one
 * of more than 4096 elements ends the program; a record HDF5 refuses (a
 * name given twice) is skipped. */
#ifndef TCB_FUZZ_H5_PROGRAM_H
#define TCB_FUZZ_H5_PROGRAM_H

#include <stddef.h>
#include <stdint.h>

enum { H5P_I32, H5P_I64, H5P_F32, H5P_F64, H5P_U8, H5P_STR, H5P_U64, H5P_N_TYPES };
#define H5P_MAX_ELEMENTS 4096

/* Runs the program data[0..size) into a new HDF5 file at path, names[k]
 * for name index k. Aborts only when the file cannot be created. */
void h5prog_build(const uint8_t *data, size_t size, const char *const *names, int n_names, const char *path);

/* Appending records, for the seeds (make_seeds.c). A growable buffer. */
typedef struct h5prog_buf {
    uint8_t *bytes;
    size_t len, cap;
} h5prog_buf;

/* A dataset (attribute: 1) of the given numeric type and shape; data holds
 * the elements in that type, little-endian as x86 keeps them. */
void h5prog_add_array(h5prog_buf *b, int attribute, int name, int type, int rank, const int *dims, const void *data);
void h5prog_add_string(h5prog_buf *b, int attribute, int name, const char *text);

/* The program that rebuilds the HDF5 file at path: a record for each
 * dataset and root attribute of names[0..n_names) it holds, in that order
 * (a file written by the reader's own writer, checksum included, is the
 * best seed). Objects of another type (a compound) are left out; one of
 * more than the program's sizes allow, or an unreadable file, aborts. */
void h5prog_from_file(h5prog_buf *b, const char *path, const char *const *names, int n_names);

#endif

/* tcbench — reader of NumPy .npz files (numpy.savez, numpy.savez_compressed).
 *
 * An .npz is a ZIP archive whose members are .npy files, one per array:
 * np.savez(path, a=x) stores member "a.npy". np.savez writes the members
 * uncompressed (ZIP method 0, "stored"), np.savez_compressed deflates them
 * (method 8); both are read here, deflate through zlib, and each member's
 * CRC-32 is checked. numpy writes ZIP64 fields whenever an archive or a
 * member passes 4 GiB (and zipfile's force_zip64 members), so they are read
 * too. Refused with a message saying so: encrypted members, other
 * compression methods, archives split over several disks.
 *
 * Only the central directory is read on open (names and sizes), so a
 * reader can check which members exist before it reads any array; a
 * member is read and decompressed when asked for, and parsed by the .npy
 * reader (tcb/npy.h). Errors name the file, and the member where there is
 * one ("results.npz: 3.npy: ..."). */
#ifndef TCB_NPZ_H
#define TCB_NPZ_H

#include <stdint.h>
#include <stdio.h>

#include "tcb/error.h"
#include "tcb/npy.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_npz_member {
    char *name;            /* as stored, e.g. "3.npy" */
    int method;            /* 0 stored, 8 deflate */
    uint32_t crc;
    uint64_t size;         /* compressed bytes */
    uint64_t raw_size;     /* the .npy file's bytes */
    uint64_t header_at;    /* offset of the member's local header */
} tcb_npz_member;

typedef struct tcb_npz {
    char *path;
    FILE *f;
    uint64_t file_size;
    int n;
    tcb_npz_member *members;  /* [n], in the archive's order */
} tcb_npz;

/* Opens path and reads its central directory; errors name the file. */
int tcb_npz_open(const char *path, tcb_npz *z, tcb_error *err);
void tcb_npz_close(tcb_npz *z);

/* The index of the member named name, or -1. */
int tcb_npz_find(const tcb_npz *z, const char *name);

/* Member k read, checked against its CRC and parsed as .npy into *out (which
 * owns the bytes: release it with tcb_npy_free). */
int tcb_npz_read(const tcb_npz *z, int k, tcb_npy *out, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif

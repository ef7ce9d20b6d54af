/* Private to datasets/: the frame files of an OBJ directory (objdir.c). */
#ifndef TCB_DATASETS_OBJDIR_H
#define TCB_DATASETS_OBJDIR_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/sequence.h"

#define TCB_OBJDIR_NAME_MAX 256

typedef struct tcb_objdir_frame {
    char name[TCB_OBJDIR_NAME_MAX]; /* file name inside the directory */
    unsigned long long number; /* the last integer in the name: the frame order */
    long long size;          /* bytes */
    long long mtime_ns;
} tcb_objdir_frame;

/* The *.obj files of dir sorted by frame number; *frames is malloc'ed [*n].
 * Errors: unreadable dir (IO); no OBJ files, a name without a number, two
 * names with the same number, a single frame (INPUT). */
int tcb_objdir_list(const char *dir, tcb_objdir_frame **frames, int *n, tcb_error *err);

/* Parse the listed frames into a raw (unnormalized, pool-less) sequence.
 * Every frame must repeat the first frame's vertex count and faces. */
int tcb_objdir_read(const char *dir, const tcb_objdir_frame *frames, int n, const char *name,
                    tcb_sequence *out, tcb_error *err);

/* The last path component of dir (trailing slashes ignored). */
int tcb_objdir_default_name(const char *dir, char name[TCB_NAME_MAX], tcb_error *err);

#endif

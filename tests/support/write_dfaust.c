/* Test helper: writes a tiny DFAUST root in the official layout for the
 * integration tests (not installed):
 *     write_dfaust DIR
 * DIR/registrations_m.hdf5: 50002_jumping_jacks (6 frames), 50002_hips
 * DIR/registrations_f.hdf5: 50004_jumping_jacks (8 frames)
 * Each subject is the synthetic humanoid of another seed; both files hold
 * its faces. */
#include <stdio.h>

#include "dfaust_files.h"
#include "tcb/fsutil.h"

static void write_file(const char *dir, const char *name, const char *subject, uint64_t seed, int frames,
                       int with_hips)
{
    char path[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    tcb_sequence s;
    tu_dfaust_subject_frames(seed, frames, &s);
    hid_t file = tu_h5_create(path);
    tu_dfaust_write_subject(file, subject, "jumping_jacks", &s);
    if (with_hips) tu_dfaust_write_subject(file, subject, "hips", &s);
    tu_dfaust_write_faces(file, &s);
    tu_h5_close(file);
    tcb_sequence_free(&s);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: write_dfaust DIR\n");
        return 2;
    }
    write_file(argv[1], "registrations_m.hdf5", "50002", 0, 6, 1);
    write_file(argv[1], "registrations_f.hdf5", "50004", 1, 8, 0);
    return 0;
}

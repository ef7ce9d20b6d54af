#include "dfaust_files.h"

#include <stdio.h>
#include <stdlib.h>

#include "tcb/synth.h"

static void check(int ok, const char *what)
{
    if (ok) return;
    fprintf(stderr, "dfaust_files: %s failed\n", what);
    abort();
}

hid_t tu_h5_create(const char *path)
{
    hid_t file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    check(file >= 0, path);
    return file;
}

void tu_h5_close(hid_t file) { check(H5Fclose(file) >= 0, "H5Fclose"); }

void tu_h5_write(hid_t file, const char *name, hid_t type, int rank, const hsize_t *dims, const void *data)
{
    hid_t space = H5Screate_simple(rank, dims, NULL);
    check(space >= 0, name);
    hid_t ds = H5Dcreate2(file, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    check(ds >= 0 && H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0, name);
    H5Dclose(ds);
    H5Sclose(space);
}

void tu_dfaust_write_subject(hid_t file, const char *subject, const char *sequence, const tcb_sequence *s)
{
    size_t V = (size_t)s->n_verts, F = (size_t)s->n_frames;
    float *vcf = malloc(V * 3 * F * sizeof *vcf);
    check(vcf != NULL, "malloc");
    for (size_t f = 0; f < F; f++)
        for (size_t vc = 0; vc < 3 * V; vc++) vcf[vc * F + f] = s->verts[f * 3 * V + vc];
    char key[256];
    check((size_t)snprintf(key, sizeof key, "%s_%s", subject, sequence) < sizeof key, "key");
    hsize_t dims[3] = {V, 3, F};
    tu_h5_write(file, key, H5T_NATIVE_FLOAT, 3, dims, vcf);
    free(vcf);
}

void tu_dfaust_write_faces(hid_t file, const tcb_sequence *s)
{
    hsize_t dims[2] = {(hsize_t)s->n_faces, 3};
    tu_h5_write(file, "faces", H5T_NATIVE_INT32, 2, dims, s->faces);
}

void tu_dfaust_subject_frames(uint64_t seed, int n_frames, tcb_sequence *out)
{
    tcb_error err = {0};
    if (tcb_synth_generate("humanoid_jacks", seed, n_frames, out, &err)) {
        fprintf(stderr, "dfaust_files: %s\n", err.msg);
        abort();
    }
}

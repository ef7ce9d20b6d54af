/* Shared by the PyTorch cross-check helpers (atlas_export.c,
 * atlas_step_export.c): files that the Python side reads with numpy, raw
 * float32 in host order (x86 is little-endian, as the scripts read). */
#ifndef TCB_TESTS_PYTORCH_EXPORT_H
#define TCB_TESTS_PYTORCH_EXPORT_H

#include <stdio.h>

#include "methods/atlas/model.h"

enum { EXPORT_PATH_MAX = 4096 };

/* out ← DIR/NAME; 0, or 1 with a message on stderr when it does not fit. */
static inline int export_path(char out[EXPORT_PATH_MAX], const char *dir, const char *name)
{
    int n = snprintf(out, EXPORT_PATH_MAX, "%s/%s", dir, name);
    if (n >= 0 && n < EXPORT_PATH_MAX) return 0;
    fprintf(stderr, "path too long: %s/%s\n", dir, name);
    return 1;
}

/* DIR/NAME ← n items of `size` bytes at x; 0, or 1 with a message on stderr. */
static inline int export_raw(const char *dir, const char *name, const void *x, size_t size, size_t n)
{
    char path[EXPORT_PATH_MAX];
    if (export_path(path, dir, name)) return 1;
    FILE *fp = fopen(path, "wb");
    int ok = fp && fwrite(x, size, n, fp) == n;
    if (fp && fclose(fp)) ok = 0;
    if (!ok) fprintf(stderr, "cannot write %s\n", path);
    return ok ? 0 : 1;
}

static inline int export_f32(const char *dir, const char *name, const float *x, size_t n)
{
    return export_raw(dir, name, x, sizeof(float), n);
}

/* The model's weights as DIR/STEM.bin + DIR/STEM.json (tcb_atlas_model_export). */
static inline int export_model(const tcb_atlas_model *m, const char *dir, const char *stem,
                               tcb_error *err)
{
    char bin[EXPORT_PATH_MAX], json[EXPORT_PATH_MAX], name[256];
    snprintf(name, sizeof name, "%s.bin", stem);
    int rc = export_path(bin, dir, name);
    snprintf(name, sizeof name, "%s.json", stem);
    if (rc | export_path(json, dir, name))
        return tcb_fail(err, TCB_ERR_IO, "path too long under %s", dir);
    return tcb_atlas_model_export(m, bin, json, err);
}

#endif

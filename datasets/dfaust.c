/* DFAUST registration files -> a tcb_sequence with one block per subject
 * (tcb/dfaust.h). Everything is checked before it is trusted: each file
 * opens, each registration is float (V, 3, F), `faces` is integer (NF, 3)
 * with ids below V and the same in both files, so a malformed file is an
 * error naming it and the dataset, never a crash. */
#include "tcb/dfaust.h"

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "datasets/cache.h"
#include "datasets/h5util.h"
#include "datasets/strbuf.h"
#include "tcb/fsutil.h"

#define N_FILES 2
static const char *const file_names[N_FILES] = {TCB_DFAUST_FILE_M, TCB_DFAUST_FILE_F};

typedef struct dfaust_files {
    char path[N_FILES][TCB_PATH_MAX];
    hid_t id[N_FILES]; /* −1: absent from root */
} dfaust_files;

typedef struct dfaust_subject {
    char name[TCB_BLOCK_NAME_MAX];
    int file;     /* index into dfaust_files */
    int n_frames; /* the F of its registration */
} dfaust_subject;

/* ---- files ------------------------------------------------------------- */

static void close_files(dfaust_files *f)
{
    for (int k = 0; k < N_FILES; k++)
        if (f->id[k] >= 0) H5Fclose(f->id[k]);
}

static int open_files(const char *root, const char *sequence, dfaust_files *f, tcb_error *err)
{
    int found = 0;
    for (int k = 0; k < N_FILES; k++) f->id[k] = -1;
    for (int k = 0; k < N_FILES; k++) {
        int rc = tcb_path_join(f->path[k], sizeof f->path[k], err, "%s/%s", root, file_names[k]);
        if (rc) return rc;
        if (!tcb_is_file(f->path[k])) continue;
        found = 1;
        /* HDF5 refuses a file shorter than its superblock says: truncation
         * is caught here. */
        f->id[k] = H5Fopen(f->path[k], H5F_ACC_RDONLY, H5P_DEFAULT);
        if (f->id[k] < 0)
            return tcb_fail(err, TCB_ERR_INPUT,
                            "%s: not a readable HDF5 file (truncated or corrupt): "
                            "cannot look up <subject>_%s",
                            f->path[k], sequence);
    }
    if (!found)
        return tcb_fail(err, TCB_ERR_IO, "%s: neither %s nor %s found", root, file_names[0], file_names[1]);
    return TCB_OK;
}

/* "<root>/registrations_m.hdf5 and <root>/registrations_f.hdf5", or the one
 * present: what a missing dataset was looked for in. */
static void present_files(const dfaust_files *f, char *out, size_t size)
{
    int both = f->id[0] >= 0 && f->id[1] >= 0;
    snprintf(out, size, "%s%s%s", f->id[0] >= 0 ? f->path[0] : "", both ? " and " : "",
             f->id[1] >= 0 ? f->path[1] : "");
}

/* ---- which subjects ---------------------------------------------------- */

static int dataset_key(char *key, size_t size, const char *subject, const char *sequence, tcb_error *err)
{
    if (strlen(subject) >= TCB_BLOCK_NAME_MAX ||
        (size_t)snprintf(key, size, "%s_%s", subject, sequence) >= size)
        return tcb_fail(err, TCB_ERR_INPUT, "subject '%.40s' or sequence '%.40s' too long", subject,
                        sequence);
    return TCB_OK;
}

/* The file holding `key`: exactly one of them. */
static int locate(const dfaust_files *f, const char *key, int *file, tcb_error *err)
{
    *file = -1;
    for (int k = 0; k < N_FILES; k++) {
        if (f->id[k] < 0 || H5Lexists(f->id[k], key, H5P_DEFAULT) <= 0) continue;
        if (*file >= 0)
            return tcb_fail(err, TCB_ERR_INPUT, "%s and %s both hold dataset %s (a subject is in one file)",
                            f->path[*file], f->path[k], key);
        *file = k;
    }
    if (*file >= 0) return TCB_OK;
    char where[2 * TCB_PATH_MAX + 8];
    present_files(f, where, sizeof where);
    return tcb_fail(err, TCB_ERR_INPUT, "%s: no dataset %s", where, key);
}

static int find_listed(const dfaust_files *f, const char *sequence, char *const *subjects, int n,
                       dfaust_subject *out, tcb_error *err)
{
    for (int s = 0; s < n; s++) {
        char key[2 * TCB_NAME_MAX];
        int rc = dataset_key(key, sizeof key, subjects[s], sequence, err);
        if (!rc) rc = locate(f, key, &out[s].file, err);
        if (rc) return rc;
        snprintf(out[s].name, sizeof out[s].name, "%s", subjects[s]);
    }
    return TCB_OK;
}

typedef struct scan {
    const char *sequence;
    int file;
    dfaust_subject *list;
    int n, cap;
} scan;

/* H5Literate callback: keeps "<subject>_<sequence>". The subject is what
 * precedes the first '_' (ids are digits), so "50002_shake_hips" is not
 * taken for sequence "hips". */
static herr_t collect(hid_t group, const char *key, const H5L_info_t *info, void *data)
{
    (void)group, (void)info;
    scan *sc = data;
    const char *sep = strchr(key, '_');
    if (!sep || sep == key || strcmp(sep + 1, sc->sequence) != 0) return 0;
    if (sep - key >= TCB_BLOCK_NAME_MAX) return -1;
    if (sc->n == sc->cap) {
        int cap = sc->cap ? 2 * sc->cap : 16;
        dfaust_subject *p = realloc(sc->list, (size_t)cap * sizeof *p);
        if (!p) return -1;
        sc->list = p, sc->cap = cap;
    }
    dfaust_subject *s = &sc->list[sc->n++];
    memset(s, 0, sizeof *s);
    memcpy(s->name, key, (size_t)(sep - key));
    s->file = sc->file;
    return 0;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(((const dfaust_subject *)a)->name, ((const dfaust_subject *)b)->name);
}

/* Every subject of either file that performed `sequence`, sorted. */
static int find_all(const dfaust_files *f, const char *sequence, dfaust_subject **out, int *n, tcb_error *err)
{
    scan sc = {sequence, 0, NULL, 0, 0};
    for (int k = 0; k < N_FILES; k++) {
        sc.file = k;
        if (f->id[k] >= 0 && H5Literate(f->id[k], H5_INDEX_NAME, H5_ITER_INC, NULL, collect, &sc) < 0) {
            free(sc.list);
            return tcb_fail(err, TCB_ERR_INPUT, "%s: cannot list the datasets (corrupt file, or a subject id "
                            "of %d characters or more)", f->path[k], TCB_BLOCK_NAME_MAX);
        }
    }
    *out = sc.list, *n = sc.n;
    char where[2 * TCB_PATH_MAX + 8];
    present_files(f, where, sizeof where);
    if (sc.n == 0) return tcb_fail(err, TCB_ERR_INPUT, "%s: no dataset <subject>_%s", where, sequence);
    qsort(sc.list, (size_t)sc.n, sizeof *sc.list, by_name);
    for (int s = 1; s < sc.n; s++)
        if (strcmp(sc.list[s].name, sc.list[s - 1].name) == 0)
            return tcb_fail(err, TCB_ERR_INPUT,
                            "%s and %s both hold dataset %s_%s (a subject is in one file)", f->path[0],
                            f->path[1], sc.list[s].name, sequence);
    return TCB_OK;
}

/* ---- checking and reading the arrays ------------------------------------ */

static void shape_text(const tcb_h5_shape *sh, char *out, size_t size)
{
    size_t used = (size_t)snprintf(out, size, "%s array of shape (",
                                   sh->type_class == H5T_FLOAT     ? "a float"
                                   : sh->type_class == H5T_INTEGER ? "an integer"
                                                                   : "a non-numeric");
    for (int d = 0; d < sh->rank && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, "%s%llu", d ? ", " : "",
                                 (unsigned long long)sh->dims[d]);
    if (used < size) snprintf(out + used, size - used, ")");
}

/* Registration `key` is float (V, 3, F) with F ≥ 2 and V as *n_verts (set
 * by the first subject, *n_verts = 0 before). */
static int check_registration(hid_t file, const char *path, const char *key, int *n_verts, int *n_frames,
                              tcb_error *err)
{
    tcb_h5_shape sh;
    if (tcb_h5_shape_of(file, key, &sh) != 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: unreadable dataset (corrupt file)", path, key);
    char got[256];
    shape_text(&sh, got, sizeof got);
    if (sh.type_class != H5T_FLOAT || sh.rank != 3 || sh.dims[1] != 3 || sh.dims[0] < 1 ||
        sh.dims[0] > INT32_MAX / 3 || sh.dims[2] > INT32_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: expected a float array of shape (V, 3, F), got %s", path,
                        key, got);
    if (sh.dims[2] < 2)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: %llu frame(s); a subject needs at least 2", path, key,
                        (unsigned long long)sh.dims[2]);
    if (*n_verts && sh.dims[0] != (hsize_t)*n_verts)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: %llu vertices, but the first subject has %d", path, key,
                        (unsigned long long)sh.dims[0], *n_verts);
    *n_verts = (int)sh.dims[0];
    *n_frames = (int)sh.dims[2];
    return TCB_OK;
}

/* The (V, 3, F) registration into frames-major dst [F][V][3]. */
static int read_registration(hid_t file, const char *path, const char *key, int nv, int nf, float *dst,
                             tcb_error *err)
{
    size_t len = (size_t)nv * 3 * (size_t)nf;
    float *raw = malloc(len * sizeof *raw);
    if (!raw) return tcb_fail(err, TCB_ERR_NOMEM, "%s: %s: out of memory for %d frames", path, key, nf);
    hid_t ds = H5Dopen2(file, key, H5P_DEFAULT);
    herr_t st = ds < 0 ? -1 : H5Dread(ds, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, raw);
    if (ds >= 0) H5Dclose(ds);
    int rc = TCB_OK;
    if (st < 0)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: %s: cannot read (truncated or corrupt file)", path, key);
    /* raw[v][c][f] -> dst[f][v][c] */
    for (size_t vc = 0; !rc && vc < (size_t)nv * 3; vc++)
        for (int f = 0; f < nf; f++) {
            float x = raw[vc * (size_t)nf + (size_t)f];
            if (!isfinite(x)) {
                rc = tcb_fail(err, TCB_ERR_INPUT, "%s: %s: non-finite coordinate at vertex %zu, frame %d",
                              path, key, vc / 3, f);
                break;
            }
            dst[((size_t)f * (size_t)nv * 3) + vc] = x;
        }
    free(raw);
    return rc;
}

/* `faces` of one file: integer (NF, 3), every id in [0, nv). *faces is
 * malloc'ed. */
static int read_faces(hid_t file, const char *path, int nv, int32_t **faces, int *n_faces, tcb_error *err)
{
    *faces = NULL;
    if (H5Lexists(file, "faces", H5P_DEFAULT) <= 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: no dataset faces (the triangles of every registration)",
                        path);
    tcb_h5_shape sh;
    char got[256] = "an unreadable dataset";
    int ok = tcb_h5_shape_of(file, "faces", &sh) == 0;
    if (ok) shape_text(&sh, got, sizeof got);
    if (!ok || sh.type_class != H5T_INTEGER || sh.rank != 2 || sh.dims[1] != 3 || sh.dims[0] < 1 ||
        sh.dims[0] > INT32_MAX / 3)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: faces: expected an integer array of shape (NF, 3), got %s",
                        path, got);
    *n_faces = (int)sh.dims[0];
    size_t len = 3 * (size_t)*n_faces;
    if (!(*faces = malloc(len * sizeof **faces)))
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    hid_t ds = H5Dopen2(file, "faces", H5P_DEFAULT);
    herr_t st = ds < 0 ? -1 : H5Dread(ds, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, *faces);
    if (ds >= 0) H5Dclose(ds);
    if (st < 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: faces: cannot read (truncated or corrupt file)", path);
    /* Bad ids would turn into out-of-bounds reads far from here. */
    for (size_t i = 0; i < len; i++)
        if ((*faces)[i] < 0 || (*faces)[i] >= nv)
            return tcb_fail(err, TCB_ERR_INPUT, "%s: faces[%zu][%zu]: vertex id %d outside [0, %d)", path,
                            i / 3, i % 3, (int)(*faces)[i], nv);
    return TCB_OK;
}

/* The faces of every file a subject comes from; with both, they must agree. */
static int shared_faces(const dfaust_files *f, const dfaust_subject *list, int n, int nv, int32_t **faces,
                        int *n_faces, tcb_error *err)
{
    *faces = NULL, *n_faces = 0;
    int first = -1, rc = TCB_OK;
    for (int k = 0; k < N_FILES && !rc; k++) {
        int used = 0;
        for (int s = 0; s < n; s++) used |= list[s].file == k;
        if (!used) continue;
        int32_t *mine = NULL;
        int nf = 0;
        rc = read_faces(f->id[k], f->path[k], nv, &mine, &nf, err);
        if (!rc && first < 0) {
            first = k, *faces = mine, *n_faces = nf;
            continue;
        }
        if (!rc && (nf != *n_faces || memcmp(mine, *faces, 3 * (size_t)nf * sizeof *mine) != 0))
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s and %s: faces differ (every registration shares one set)",
                          f->path[first], f->path[k]);
        free(mine);
    }
    return rc;
}

/* ---- the sequence ----------------------------------------------------- */

/* Every listed registration's shape: the vertex count and the frames in all. */
static int measure_subjects(const dfaust_files *f, const char *sequence, dfaust_subject *list, int n, int *nv,
                            int *total, tcb_error *err)
{
    int rc = TCB_OK;
    char key[2 * TCB_NAME_MAX];
    *nv = *total = 0;
    for (int s = 0; s < n && !rc; s++) {
        int k = list[s].file;
        rc = dataset_key(key, sizeof key, list[s].name, sequence, err);
        if (!rc) rc = check_registration(f->id[k], f->path[k], key, nv, &list[s].n_frames, err);
        if (!rc && list[s].n_frames > INT32_MAX - *total)
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s: more than %d frames in all", sequence, INT32_MAX);
        if (!rc) *total += list[s].n_frames;
    }
    return rc;
}

/* Shapes first (so nothing large is read from a file with a bad one), then
 * the faces, then the frames, block after block. */
static int read_subjects(const dfaust_files *f, const char *sequence, dfaust_subject *list, int n,
                         tcb_sequence *out, tcb_error *err)
{
    int nv, total;
    char key[2 * TCB_NAME_MAX];
    int rc = measure_subjects(f, sequence, list, n, &nv, &total, err);
    int32_t *faces = NULL;
    int n_faces = 0;
    if (!rc) rc = shared_faces(f, list, n, nv, &faces, &n_faces, err);
    if (!rc) rc = tcb_sequence_alloc(out, sequence, total, nv, n_faces, err);
    if (!rc) memcpy(out->faces, faces, 3 * (size_t)n_faces * sizeof *faces);
    free(faces);
    if (!rc && !(out->blocks = calloc((size_t)n, sizeof *out->blocks)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: out of memory", sequence);
    for (int s = 0, start = 0; s < n && !rc; start += list[s++].n_frames) {
        tcb_block *b = &out->blocks[out->n_blocks++];
        snprintf(b->name, sizeof b->name, "%s", list[s].name);
        b->start = start, b->n_frames = list[s].n_frames;
        float *dst = out->verts + (size_t)start * (size_t)nv * 3;
        int k = list[s].file;
        rc = dataset_key(key, sizeof key, list[s].name, sequence, err);
        if (!rc) rc = read_registration(f->id[k], f->path[k], key, nv, b->n_frames, dst, err);
    }
    /* Listed subjects may repeat; found ones cannot. */
    if (!rc) rc = tcb_blocks_check(out->blocks, out->n_blocks, out->n_frames, "subjects", err);
    return rc;
}

/* The files of root and the subjects of the request, listed (in their
 * order) or found (sorted); the caller frees *list and closes f. */
static int open_subjects(const char *root, const char *sequence, char *const *subjects, int n_subjects,
                         dfaust_files *f, dfaust_subject **list, int *n, tcb_error *err)
{
    *list = NULL, *n = n_subjects;
    int rc = open_files(root, sequence, f, err);
    if (rc) return rc;
    if (!n_subjects) return find_all(f, sequence, list, n, err);
    if (!(*list = calloc((size_t)n_subjects, sizeof **list)))
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", sequence);
    return find_listed(f, sequence, subjects, n_subjects, *list, err);
}

int tcb_dfaust_read(const char *root, const char *sequence, char *const *subjects, int n_subjects,
                    tcb_sequence *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    tcb_h5_quiet q;
    tcb_h5_quiet_begin(&q);
    dfaust_files f;
    dfaust_subject *list;
    int n, rc = open_subjects(root, sequence, subjects, n_subjects, &f, &list, &n, err);
    if (!rc) rc = read_subjects(&f, sequence, list, n, out, err);
    free(list);
    close_files(&f);
    tcb_h5_quiet_end(&q);
    if (rc) tcb_sequence_free(out);
    return rc;
}

int tcb_dfaust_probe(const char *root, const char *sequence, char *const *subjects, int n_subjects, int *n_frames,
                     int *n_verts, tcb_error *err)
{
    tcb_h5_quiet q;
    tcb_h5_quiet_begin(&q);
    dfaust_files f;
    dfaust_subject *list;
    int n, rc = open_subjects(root, sequence, subjects, n_subjects, &f, &list, &n, err);
    if (!rc) rc = measure_subjects(&f, sequence, list, n, n_verts, n_frames, err);
    free(list);
    close_files(&f);
    tcb_h5_quiet_end(&q);
    return rc;
}

/* ---- loading through the cache ---------------------------------------- */

typedef struct dfaust_request {
    const char *root;
    char *const *subjects;
    int n_subjects;
} dfaust_request;

static int read_request(const void *ctx, const char *name, tcb_sequence *out, tcb_error *err)
{
    const dfaust_request *r = ctx;
    return tcb_dfaust_read(r->root, name, r->subjects, r->n_subjects, out, err);
}

/* The cache key's source: the subject selection and both files' sizes and
 * mtimes (a file that appears, goes or changes reads afresh). */
static int describe_source(const dfaust_request *r, tcb_strbuf *b)
{
    int bad = tcb_sb_printf(b, "dfaust subjects=%s", r->n_subjects ? "" : "(all)");
    for (int s = 0; s < r->n_subjects && !bad; s++)
        bad = tcb_sb_printf(b, "%s%s", s ? "," : "", r->subjects[s]);
    for (int k = 0; k < N_FILES && !bad; k++) {
        char path[TCB_PATH_MAX];
        struct stat st;
        if ((size_t)snprintf(path, sizeof path, "%s/%s", r->root, file_names[k]) >= sizeof path ||
            stat(path, &st) != 0)
            bad = tcb_sb_printf(b, "\n%s absent", file_names[k]);
        else
            bad = tcb_sb_printf(b, "\n%s %lld %lld", file_names[k], (long long)st.st_size,
                                (long long)st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec);
    }
    return bad || tcb_sb_printf(b, "\n") ? -1 : 0;
}

int tcb_sequence_load_dfaust(const char *root, const char *sequence, char *const *subjects, int n_subjects,
                             const tcb_load_opts *opts, tcb_sequence *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    dfaust_request r = {root, subjects, n_subjects};
    tcb_strbuf source = {0};
    int rc = describe_source(&r, &source) == 0
                 ? tcb_cache_load(sequence, opts, source.s, read_request, &r, out, err)
                 : tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", root);
    free(source.s);
    return rc;
}

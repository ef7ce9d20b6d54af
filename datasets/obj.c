/* Wavefront OBJ reader and writer.
 *
 * The reader parses the whole file from one buffer: each line is cut into a
 * C string in place (its '\n' and any '#' comment become NUL), so strtof and
 * strtol can never run into the next line. Only positions and triangles are
 * kept; texture and normal indices are checked for syntax and dropped. */
#include "tcb/mesh_io.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"

typedef struct obj_parser {
    const char *path;
    int line;
    tcb_error *err;
    float *verts;     /* [cap_v][3] */
    int nv, cap_v;
    int32_t *faces;   /* [cap_f][3] */
    int nf, cap_f;
    int32_t *poly;    /* [cap_p] vertex ids of the face being read */
    int cap_p;
    long max_index;   /* largest 1-based positive index seen, and where */
    int max_index_line;
} obj_parser;

static int is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

static char *skip_blanks(char *p)
{
    while (is_blank(*p)) p++;
    return p;
}

static int fail(obj_parser *ps, const char *what)
{
    return tcb_fail(ps->err, TCB_ERR_INPUT, "%s:%d: %s", ps->path, ps->line, what);
}

/* buf (elements of `elem` bytes) grown to hold at least `need`; NULL with
 * *rc set when the size is absurd or memory runs out. */
static void *grow(obj_parser *ps, void *buf, int *cap, int need, size_t elem, int *rc)
{
    if (need <= *cap) return buf;
    if (need > INT_MAX / 8) {
        *rc = tcb_fail(ps->err, TCB_ERR_INPUT, "%s:%d: too many elements", ps->path, ps->line);
        return NULL;
    }
    int cap2 = *cap ? *cap : 1024;
    while (cap2 < need) cap2 *= 2;
    void *p = realloc(buf, (size_t)cap2 * elem);
    if (!p) {
        *rc = tcb_fail(ps->err, TCB_ERR_NOMEM, "%s: out of memory", ps->path);
        return NULL;
    }
    *cap = cap2;
    return p;
}

/* One number token at *p (after blanks); it must end at a blank or NUL. */
static int parse_float(obj_parser *ps, char **p, float *out)
{
    char *s = skip_blanks(*p), *end;
    if (!*s) return fail(ps, "vertex needs 3 coordinates");
    *out = strtof(s, &end);
    if (end == s || (*end && !is_blank(*end))) return fail(ps, "bad number in vertex");
    if (!isfinite(*out)) return fail(ps, "vertex coordinate is NaN or infinite");
    *p = end;
    return TCB_OK;
}

static int parse_vertex(obj_parser *ps, char *p)
{
    int rc = TCB_OK;
    float *grown = grow(ps, ps->verts, &ps->cap_v, ps->nv + 1, 3 * sizeof(float), &rc);
    if (!grown) return rc;
    ps->verts = grown;
    float *v = ps->verts + 3 * (size_t)ps->nv;
    for (int d = 0; d < 3; d++)
        if ((rc = parse_float(ps, &p, &v[d]))) return rc;
    /* Optional w or per-vertex colour: must be numbers, otherwise ignored. */
    for (p = skip_blanks(p); *p; p = skip_blanks(p)) {
        float extra;
        if ((rc = parse_float(ps, &p, &extra))) return rc;
    }
    ps->nv++;
    return TCB_OK;
}

/* An integer at *p (no leading blanks allowed: the caller positions it). */
static int parse_int(obj_parser *ps, char **p, long *out)
{
    char *end;
    if (!(**p == '-' || **p == '+' || (**p >= '0' && **p <= '9')))
        return fail(ps, "bad index in face");
    *out = strtol(*p, &end, 10);
    if (end == *p) return fail(ps, "bad index in face");
    *p = end;
    return TCB_OK;
}

/* A vertex reference `v`, `v/vt`, `v//vn` or `v/vt/vn`, resolved to a
 * 0-based id. Positive ids are range-checked once the file is read (some
 * writers put faces before vertices); negative ids are relative to the
 * vertices read so far. */
static int parse_ref(obj_parser *ps, char **p, int32_t *id)
{
    long v, ignored;
    int rc = parse_int(ps, p, &v);
    if (rc) return rc;
    if (**p == '/') {
        (*p)++;
        if (**p != '/' && (rc = parse_int(ps, p, &ignored))) return rc;
        if (**p == '/') {
            (*p)++;
            if ((rc = parse_int(ps, p, &ignored))) return rc;
        }
    }
    if (**p && !is_blank(**p)) return fail(ps, "bad index in face");
    if (v == 0) return fail(ps, "vertex index 0 (OBJ indices start at 1)");
    if (v > INT_MAX || v < -(long)ps->nv)
        return tcb_fail(ps->err, TCB_ERR_INPUT, "%s:%d: vertex index %ld out of range (%d vertices so far)",
                        ps->path, ps->line, v, ps->nv);
    if (v < 0) {
        *id = (int32_t)(ps->nv + v);
    } else {
        *id = (int32_t)(v - 1);
        if (v > ps->max_index) {
            ps->max_index = v;
            ps->max_index_line = ps->line;
        }
    }
    return TCB_OK;
}

static int parse_face(obj_parser *ps, char *p)
{
    int n = 0, rc = TCB_OK;
    for (p = skip_blanks(p); *p; p = skip_blanks(p)) {
        int32_t *poly = grow(ps, ps->poly, &ps->cap_p, n + 1, sizeof(int32_t), &rc);
        if (!poly) return rc;
        ps->poly = poly;
        if ((rc = parse_ref(ps, &p, &ps->poly[n]))) return rc;
        n++;
    }
    if (n < 3)
        return tcb_fail(ps->err, TCB_ERR_INPUT, "%s:%d: face has %d vertices, needs at least 3",
                        ps->path, ps->line, n);
    int32_t *faces = grow(ps, ps->faces, &ps->cap_f, ps->nf + n - 2, 3 * sizeof(int32_t), &rc);
    if (!faces) return rc;
    ps->faces = faces;
    for (int i = 1; i + 1 < n; i++) { /* fan around the first corner */
        int32_t *t = ps->faces + 3 * (size_t)ps->nf++;
        t[0] = ps->poly[0];
        t[1] = ps->poly[i];
        t[2] = ps->poly[i + 1];
    }
    return TCB_OK;
}

static int ignored_statement(const char *kw, size_t len)
{
    static const char *const names[] = {"vt", "vn", "vp", "o", "g", "s", "usemtl", "mtllib", "l", "p"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strlen(names[i]) == len && memcmp(kw, names[i], len) == 0) return 1;
    return 0;
}

static int parse_line(obj_parser *ps, char *line)
{
    char *hash = strchr(line, '#');
    if (hash) *hash = '\0';
    char *kw = skip_blanks(line), *p = kw;
    while (*p && !is_blank(*p)) p++;
    size_t len = (size_t)(p - kw);
    if (len == 0) return TCB_OK;
    if (len == 1 && kw[0] == 'v') return parse_vertex(ps, p);
    if (len == 1 && kw[0] == 'f') return parse_face(ps, p);
    if (ignored_statement(kw, len)) return TCB_OK;
    return tcb_fail(ps->err, TCB_ERR_INPUT, "%s:%d: unsupported statement '%.*s'", ps->path,
                    ps->line, (int)(len > 32 ? 32 : len), kw);
}

static int parse_buffer(obj_parser *ps, char *text, size_t len)
{
    /* A NUL would silently end the text early: report where it sits. */
    const char *nul = memchr(text, '\0', len);
    if (nul) {
        for (const char *c = text; c < nul; c++) ps->line += *c == '\n';
        ps->line++;
        return fail(ps, "NUL byte (binary data?)");
    }
    for (char *line = text; *line;) {
        char *nl = strchr(line, '\n');
        if (nl) *nl = '\0';
        ps->line++;
        int rc = parse_line(ps, line);
        if (rc) return rc;
        if (!nl) break;
        line = nl + 1;
    }
    if (ps->line == 0) ps->line = 1; /* an empty file still has a line 1 */
    if (ps->nv == 0) return fail(ps, "end of file without any vertex");
    if (ps->max_index > ps->nv)
        return tcb_fail(ps->err, TCB_ERR_INPUT, "%s:%d: vertex index %ld out of range (file has %d vertices)",
                        ps->path, ps->max_index_line, ps->max_index, ps->nv);
    if (ps->nf == 0) return fail(ps, "end of file without any face");
    return TCB_OK;
}

int tcb_obj_read(const char *path, tcb_mesh *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    char *text;
    size_t len;
    int rc = tcb_read_file(path, &text, &len, err);
    if (rc) return rc;
    obj_parser ps = {.path = path, .err = err};
    rc = parse_buffer(&ps, text, len);
    free(text);
    free(ps.poly);
    if (rc) {
        free(ps.verts);
        free(ps.faces);
        return rc;
    }
    out->n_verts = ps.nv;
    out->n_faces = ps.nf;
    out->verts = ps.verts;
    out->faces = ps.faces;
    return TCB_OK;
}

int tcb_obj_write(const char *path, const float *verts, int nv, const int32_t *faces, int nf,
                  tcb_error *err)
{
    tcb_atomic_file af;
    int rc = tcb_atomic_open(&af, path, err);
    if (rc) return rc;
    /* %.9g round-trips every float exactly. */
    for (int i = 0; i < nv; i++) {
        const float *v = verts + 3 * (size_t)i;
        fprintf(af.fp, "v %.9g %.9g %.9g\n", v[0], v[1], v[2]);
    }
    for (int i = 0; i < nf; i++) {
        const int32_t *f = faces + 3 * (size_t)i;
        fprintf(af.fp, "f %d %d %d\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    return tcb_atomic_commit(&af, err);
}

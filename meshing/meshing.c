/* tcb/meshing.h: checks the input, loads the Open3D module beside
 * libtcbench for the one call, and checks what comes back. */
#define _GNU_SOURCE /* dladdr */
#include "tcb/meshing.h"

#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshing/backend.h"
#include "meshing/meshing_internal.h"
#include "tcb/geometry.h"
#include "tcb/locate.h"

/* The module lives in the directory of the libtcbench that holds this code
 * (build tree or install prefix alike), so it is found by that path rather
 * than by the loader's search path. */
static void module_path(char *out, size_t size)
{
    Dl_info info;
    const char *self = NULL;
    if (dladdr((const void *)module_path, &info) && info.dli_fname) self = info.dli_fname;
    const char *slash = self ? strrchr(self, '/') : NULL;
    if (slash)
        snprintf(out, size, "%.*s/%s", (int)(slash - self), self, TCB_MESHING_MODULE);
    else
        snprintf(out, size, "%s", TCB_MESHING_MODULE);
}

typedef struct backend {
    void *handle;
    const tcb_meshing_ops *ops;
} backend;

/* Open3D loads ~100 shared libraries; they are mapped for the call and
 * released after it (the loader keeps what cannot be unloaded). */
static int backend_open(backend *b, tcb_error *err)
{
    char path[4096];
    module_path(path, sizeof path);
    b->handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!b->handle)
        return tcb_fail(err, TCB_ERR_UNSUPPORTED,
                        "meshing: cannot load the Open3D module: %s (scripts/setup.sh installs libopen3d-dev; "
                        "build the target tcbench_meshing)",
                        dlerror());
    tcb_meshing_entry_fn entry;
    *(void **)&entry = dlsym(b->handle, TCB_MESHING_ENTRY); /* POSIX-sanctioned cast of a data pointer */
    b->ops = entry ? entry() : NULL;
    if (!b->ops) {
        dlclose(b->handle);
        return tcb_fail(err, TCB_ERR_UNSUPPORTED, "meshing: %s has no symbol %s", path, TCB_MESHING_ENTRY);
    }
    return TCB_OK;
}

static void backend_close(backend *b) { dlclose(b->handle); }

static int check_points(const float *pts, int n, int min_n, tcb_error *err)
{
    if (!pts || n < min_n) return tcb_fail(err, TCB_ERR_INPUT, "meshing: %d points, need at least %d", n, min_n);
    if (!tcb_all_finite(pts, (size_t)3 * n))
        return tcb_fail(err, TCB_ERR_NUMERIC, "meshing: a point coordinate is not finite");
    float lo[3], hi[3];
    for (int d = 0; d < 3; d++) lo[d] = hi[d] = pts[d];
    for (int i = 1; i < n; i++)
        for (int d = 0; d < 3; d++) {
            lo[d] = fminf(lo[d], pts[3 * i + d]);
            hi[d] = fmaxf(hi[d], pts[3 * i + d]);
        }
    if (hi[0] == lo[0] && hi[1] == lo[1] && hi[2] == lo[2])
        return tcb_fail(err, TCB_ERR_INPUT, "meshing: all %d points coincide", n);
    return TCB_OK;
}

static int check_normals(const float *normals, int n, tcb_error *err)
{
    if (!normals) return tcb_fail(err, TCB_ERR_INPUT, "meshing: no normals given");
    if (!tcb_all_finite(normals, (size_t)3 * n))
        return tcb_fail(err, TCB_ERR_NUMERIC, "meshing: a normal is not finite");
    for (int i = 0; i < n; i++) {
        const float *u = normals + 3 * i;
        if (u[0] == 0 && u[1] == 0 && u[2] == 0)
            return tcb_fail(err, TCB_ERR_INPUT, "meshing: normal %d is zero", i);
    }
    return TCB_OK;
}

int tcb_meshing_check_mesh(const tcb_mesh *m, tcb_error *err)
{
    if (!m || !m->verts || !m->faces || m->n_verts < 3 || m->n_faces < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "meshing: the mesh is empty (%d vertices, %d faces)", m ? m->n_verts : 0,
                        m ? m->n_faces : 0);
    if (!tcb_all_finite(m->verts, (size_t)3 * m->n_verts))
        return tcb_fail(err, TCB_ERR_NUMERIC, "meshing: a vertex coordinate is not finite");
    for (int i = 0; i < 3 * m->n_faces; i++)
        if (m->faces[i] < 0 || m->faces[i] >= m->n_verts)
            return tcb_fail(err, TCB_ERR_INPUT, "meshing: face %d names vertex %d of %d", i / 3, m->faces[i],
                            m->n_verts);
    return TCB_OK;
}

/* What a backend returns is checked like any method's output. */
static int check_result(const tcb_mesh *m, const char *what, tcb_error *err)
{
    if (m->n_faces < 1) return tcb_fail(err, TCB_ERR_NUMERIC, "meshing: %s produced no surface", what);
    if (!tcb_all_finite(m->verts, (size_t)3 * m->n_verts))
        return tcb_fail(err, TCB_ERR_NUMERIC, "meshing: %s produced a non-finite vertex", what);
    return TCB_OK;
}

int tcb_poisson_reconstruct(const float *pts, const float *normals, int n, int depth, tcb_mesh *out,
                            tcb_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_points(pts, n, 4, err);
    if (!rc) rc = check_normals(normals, n, err);
    if (rc) return rc;
    if (depth < TCB_POISSON_DEPTH_MIN || depth > TCB_POISSON_DEPTH_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "meshing: Poisson depth %d is outside [%d, %d]", depth,
                        TCB_POISSON_DEPTH_MIN, TCB_POISSON_DEPTH_MAX);
    backend b;
    if ((rc = backend_open(&b, err))) return rc;
    rc = b.ops->poisson(pts, normals, n, depth, out, err);
    backend_close(&b);
    if (!rc) rc = check_result(out, "Poisson reconstruction", err);
    if (rc) tcb_mesh_free(out);
    return rc;
}

int tcb_mesh_remesh(const tcb_mesh *in, double edge_length, int iterations, tcb_mesh *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = tcb_meshing_check_mesh(in, err);
    if (rc) return rc;
    if (!(edge_length > 0) || !isfinite(edge_length))
        return tcb_fail(err, TCB_ERR_INPUT, "meshing: a target edge length of %g (need a positive length)",
                        edge_length);
    if (iterations < 1 || iterations > TCB_REMESH_ITERATIONS_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "meshing: %d remeshing iterations (need 1 to %d)", iterations,
                        TCB_REMESH_ITERATIONS_MAX);
    /* More faces than the input's area allows at this length is a length
     * far too short for the mesh, not a remeshing. */
    double area = tcb_mesh_area(in->verts, in->faces, in->n_faces);
    double faces = area / (0.4330127 * edge_length * edge_length); /* equilateral: √3/4 h² */
    if (faces > TCB_REMESH_FACES_MAX)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "meshing: remeshing to edge length %g would make about %.0f triangles (at most %d)",
                        edge_length, faces, TCB_REMESH_FACES_MAX);
    backend b;
    if ((rc = backend_open(&b, err))) return rc;
    rc = b.ops->remesh(in, edge_length, iterations, out, err);
    backend_close(&b);
    if (!rc) rc = check_result(out, "isotropic remeshing", err);
    if (rc) tcb_mesh_free(out);
    return rc;
}

int tcb_mesh_decimate(const tcb_mesh *in, int max_faces, tcb_mesh *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = tcb_meshing_check_mesh(in, err);
    if (rc) return rc;
    if (max_faces < 4)
        return tcb_fail(err, TCB_ERR_INPUT, "meshing: a budget of %d triangles (need at least 4)", max_faces);
    backend b;
    if ((rc = backend_open(&b, err))) return rc;
    rc = b.ops->decimate(in, max_faces, out, err);
    backend_close(&b);
    if (!rc) rc = check_result(out, "decimation", err);
    if (rc) tcb_mesh_free(out);
    return rc;
}

/* The sign that makes Σ n_i·(p_i − c) positive, c the points' mean. */
static void orient_outward(const float *pts, int n, float *normals)
{
    double c[3] = {0, 0, 0}, flux = 0;
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) c[d] += pts[3 * i + d] / (double)n;
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) flux += normals[3 * i + d] * (pts[3 * i + d] - c[d]);
    if (flux < 0)
        for (int i = 0; i < 3 * n; i++) normals[i] = -normals[i];
}

int tcb_estimate_normals(const float *pts, int n, int k, float *normals, tcb_error *err)
{
    int rc = check_points(pts, n, 4, err);
    if (rc) return rc;
    if (k < 3) return tcb_fail(err, TCB_ERR_INPUT, "meshing: %d neighbours for a normal (need at least 3)", k);
    if (!normals) return tcb_fail(err, TCB_ERR_INPUT, "meshing: no array for the normals");
    backend b;
    if ((rc = backend_open(&b, err))) return rc;
    rc = b.ops->normals(pts, n, k < n ? k : n, normals, err);
    backend_close(&b);
    if (rc) return rc;
    if (!tcb_all_finite(normals, (size_t)3 * n))
        return tcb_fail(err, TCB_ERR_NUMERIC, "meshing: normal estimation produced a non-finite normal");
    orient_outward(pts, n, normals);
    return TCB_OK;
}

/* Each face wound so that its normal points away from c, a point inside
 * the convex hull (the mean of its vertices): the right winding for every
 * face of a convex surface. */
static void wind_outward(tcb_mesh *m)
{
    double c[3] = {0, 0, 0};
    for (int i = 0; i < m->n_verts; i++)
        for (int d = 0; d < 3; d++) c[d] += m->verts[3 * i + d] / (double)m->n_verts;
    for (int f = 0; f < m->n_faces; f++) {
        int32_t *t = m->faces + 3 * f;
        const float *a = m->verts + 3 * t[0], *b = m->verts + 3 * t[1], *e = m->verts + 3 * t[2];
        double u[3], v[3], w[3];
        for (int d = 0; d < 3; d++) u[d] = b[d] - a[d], v[d] = e[d] - a[d], w[d] = a[d] - c[d];
        double nx = u[1] * v[2] - u[2] * v[1], ny = u[2] * v[0] - u[0] * v[2], nz = u[0] * v[1] - u[1] * v[0];
        if (nx * w[0] + ny * w[1] + nz * w[2] < 0) {
            int32_t x = t[1];
            t[1] = t[2], t[2] = x;
        }
    }
}

int tcb_convex_hull(const float *pts, int n, tcb_mesh *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_points(pts, n, 4, err);
    if (rc) return rc;
    backend b;
    if ((rc = backend_open(&b, err))) return rc;
    rc = b.ops->convex_hull(pts, n, out, err);
    backend_close(&b);
    if (!rc) rc = check_result(out, "the convex hull", err);
    if (rc) {
        tcb_mesh_free(out);
        return rc;
    }
    wind_outward(out);
    return TCB_OK;
}

/* Unit directions spread evenly over the sphere: the Fibonacci lattice
 * (golden-angle spiral), k of them. */
static void sphere_directions(int k, double *dirs)
{
    const double golden = M_PI * (3.0 - sqrt(5.0));
    for (int i = 0; i < k; i++) {
        double z = 1.0 - (2.0 * i + 1.0) / k, r = sqrt(1.0 - z * z);
        dirs[3 * i] = r * cos(golden * i), dirs[3 * i + 1] = r * sin(golden * i), dirs[3 * i + 2] = z;
    }
}

int tcb_convex_offset(const float *pts, int n, double offset, tcb_mesh *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(offset > 0) || !isfinite(offset))
        return tcb_fail(err, TCB_ERR_INPUT, "meshing: an offset of %g (need a positive distance)", offset);
    tcb_mesh hull;
    int rc = tcb_convex_hull(pts, n, &hull, err);
    if (rc) return rc;
    size_t m = (size_t)hull.n_verts * TCB_OFFSET_DIRECTIONS;
    double dirs[3 * TCB_OFFSET_DIRECTIONS];
    float *sum = malloc(m * 3 * sizeof *sum);
    if (!sum) {
        tcb_mesh_free(&hull);
        return tcb_fail(err, TCB_ERR_NOMEM, "meshing: out of memory for an offset of %d points", hull.n_verts);
    }
    sphere_directions(TCB_OFFSET_DIRECTIONS, dirs);
    for (int i = 0; i < hull.n_verts; i++)
        for (int k = 0; k < TCB_OFFSET_DIRECTIONS; k++)
            for (int d = 0; d < 3; d++)
                sum[3 * ((size_t)i * TCB_OFFSET_DIRECTIONS + k) + d] =
                    (float)(hull.verts[3 * i + d] + offset * dirs[3 * k + d]);
    tcb_mesh_free(&hull);
    rc = tcb_convex_hull(sum, (int)m, out, err);
    free(sum);
    return rc;
}


/* Each face's outward unit normal and offset: the plane n·x = o. */
static int face_planes(const tcb_mesh *m, double *planes, tcb_error *err)
{
    for (int f = 0; f < m->n_faces; f++) {
        const int32_t *t = m->faces + 3 * f;
        const float *a = m->verts + 3 * t[0], *b = m->verts + 3 * t[1], *c = m->verts + 3 * t[2];
        double u[3], v[3];
        for (int d = 0; d < 3; d++) u[d] = (double)b[d] - a[d], v[d] = (double)c[d] - a[d];
        double nrm[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        double len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        if (!(len > 0)) return tcb_fail(err, TCB_ERR_INPUT, "meshing: face %d of the convex surface has no area", f);
        double *p = planes + 4 * f;
        for (int d = 0; d < 3; d++) p[d] = nrm[d] / len;
        p[3] = p[0] * a[0] + p[1] * a[1] + p[2] * a[2];
    }
    return TCB_OK;
}

static int inside_planes(const double *planes, int nf, const float *q)
{
    for (int f = 0; f < nf; f++) {
        const double *p = planes + 4 * f;
        if (p[0] * q[0] + p[1] * q[1] + p[2] * q[2] > p[3]) return 0;
    }
    return 1;
}

int tcb_convex_signed_distance(const tcb_mesh *hull, const float *queries, int n, float *sd, tcb_error *err)
{
    int rc = tcb_meshing_check_mesh(hull, err);
    if (rc) return rc;
    if (n < 1 || !queries) return tcb_fail(err, TCB_ERR_INPUT, "meshing: %d query points", n);
    if (!tcb_all_finite(queries, (size_t)3 * n))
        return tcb_fail(err, TCB_ERR_NUMERIC, "meshing: a query point coordinate is not finite");
    double *planes = malloc((size_t)hull->n_faces * 4 * sizeof *planes);
    tcb_surface_point *loc = malloc((size_t)n * sizeof *loc);
    if (!planes || !loc) {
        free(planes), free(loc);
        return tcb_fail(err, TCB_ERR_NOMEM, "meshing: out of memory for the distances of %d points", n);
    }
    rc = face_planes(hull, planes, err);
    if (!rc) rc = tcb_mesh_locate(hull->verts, hull->n_verts, hull->faces, hull->n_faces, queries, n, loc, sd, err);
    for (int i = 0; !rc && i < n; i++) {
        float d = sqrtf(sd[i]);
        sd[i] = inside_planes(planes, hull->n_faces, queries + 3 * i) ? -d : d;
    }
    free(planes), free(loc);
    return rc;
}

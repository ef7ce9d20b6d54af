/* Non-isometry of a sequence's frames against frame 0 (tcb/distortion.h). */
#include "tcb/distortion.h"

#include <math.h>
#include <stdlib.h>

#include "tcb/geodesic.h"
#include "tcb/geometry.h"

/* The fields of the sources on one frame: dist [SOURCES][nv]. */
static int source_fields(const tcb_edge_graph *g, const float *verts, double *w, double *dist,
                         tcb_error *err)
{
    tcb_edge_graph_lengths(g, verts, w);
    for (int k = 0; k < TCB_DISTORTION_SOURCES; k++) {
        int src = (int)((long long)k * g->n_verts / TCB_DISTORTION_SOURCES);
        int rc = tcb_geodesic_field(g, w, src, dist + (size_t)k * (size_t)g->n_verts, err);
        if (rc) return rc;
    }
    return TCB_OK;
}

/* Edge terms: w0, wf are the CSR lengths, each undirected edge twice, so
 * the means over entries are the means over edges. */
static void edge_change(const tcb_edge_graph *g, const double *w0, const double *wf,
                        tcb_distortion *d)
{
    double sum = 0.0;
    long long n = 0;
    for (int e = 0; e < 2 * g->n_edges; e++) {
        if (!(w0[e] > 0.0)) continue;
        double c = fabs(wf[e] / w0[e] - 1.0);
        sum += c;
        n++;
        if (c > d->edge_max) d->edge_max = c;
    }
    d->edge_mean = n ? sum / (double)n : 0.0;
}

static double geo_change(size_t n, const double *g0, const double *gf)
{
    double sum = 0.0;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (!(g0[i] > 0.0) || !isfinite(g0[i]) || !isfinite(gf[i])) continue;
        sum += fabs(gf[i] / g0[i] - 1.0);
        m++;
    }
    return m ? sum / (double)m : 0.0;
}

int tcb_sequence_distortion(const tcb_sequence *s, tcb_distortion *out, tcb_error *err)
{
    tcb_edge_graph g;
    int rc = tcb_edge_graph_build(s->faces, s->n_faces, s->n_verts, &g, err);
    if (rc) return rc;
    size_t nw = 2 * (size_t)g.n_edges, nd = (size_t)TCB_DISTORTION_SOURCES * (size_t)s->n_verts;
    double *w0 = malloc(nw * sizeof *w0), *wf = malloc(nw * sizeof *wf);
    double *g0 = malloc(nd * sizeof *g0), *gf = malloc(nd * sizeof *gf);
    if (!w0 || !wf || !g0 || !gf)
        rc = tcb_fail(err, TCB_ERR_NOMEM, "distortion of %s: out of memory", s->name);
    size_t stride = (size_t)s->n_verts * 3;
    if (!rc) rc = source_fields(&g, s->verts, w0, g0, err);
    double area0 = tcb_mesh_area(s->verts, s->faces, s->n_faces);
    for (int f = 0; !rc && f < s->n_frames; f++) {
        const float *v = s->verts + (size_t)f * stride;
        rc = source_fields(&g, v, wf, gf, err);
        if (rc) break;
        tcb_distortion *d = &out[f];
        d->edge_max = 0.0;
        edge_change(&g, w0, wf, d);
        d->geo_mean = geo_change(nd, g0, gf);
        d->area_ratio = area0 > 0.0 ? tcb_mesh_area(v, s->faces, s->n_faces) / area0 : NAN;
    }
    free(w0);
    free(wf);
    free(g0);
    free(gf);
    tcb_edge_graph_free(&g);
    return rc;
}

/* What tcb/method.h promises of a method's surface of one frame, checked
 * before `tcbench frames` draws it or the reconstruction metrics sample
 * it. A mesh without charts (n_charts 0) has neither uv nor chart. */
#include "scoring/scoring.h"
#include "tcb/geometry.h"

static int faces_valid(const tcb_uv_mesh *m)
{
    for (size_t k = 0; k < 3 * (size_t)m->n_faces; k++)
        if (m->faces[k] < 0 || m->faces[k] >= m->n_verts) return 0;
    for (size_t t = 0; m->chart && t < (size_t)m->n_faces; t++) {
        const int32_t *v = m->faces + 3 * t;
        if (m->chart[v[0]] != m->chart[v[1]] || m->chart[v[0]] != m->chart[v[2]]) return 0;
    }
    return 1;
}

static int charts_valid(const tcb_uv_mesh *m)
{
    for (size_t k = 0; m->chart && k < (size_t)m->n_verts; k++) {
        float u = m->uv[2 * k], v = m->uv[2 * k + 1];
        if (m->chart[k] < 0 || m->chart[k] >= m->n_charts || !(u >= 0 && u <= 1 && v >= 0 && v <= 1)) return 0;
    }
    return 1;
}

/* Charts and their arrays agree: both arrays with 1 to max_charts charts,
 * neither with none. */
static int parametrisation_present(const tcb_uv_mesh *m, int max_charts)
{
    if (m->n_charts == 0) return !m->uv && !m->chart;
    return m->n_charts >= 1 && m->n_charts <= max_charts && m->uv && m->chart;
}

int tcb_surface_check(const tcb_uv_mesh *m, int frame, int max_charts, tcb_error *merr)
{
    if (m->n_verts < 3 || m->n_faces < 1 || !m->verts || !m->faces || !parametrisation_present(m, max_charts))
        return tcb_fail(merr, TCB_ERR_INTERNAL,
                        "surface of frame %d: %d vertices, %d faces, %d charts (0 without uv and chart, or 1 to "
                        "%d with both) or a NULL array",
                        frame, m->n_verts, m->n_faces, m->n_charts, max_charts);
    if (!tcb_all_finite(m->verts, 3 * (size_t)m->n_verts))
        return tcb_fail(merr, TCB_ERR_NUMERIC, "surface of frame %d: a non-finite vertex", frame);
    if (!charts_valid(m))
        return tcb_fail(merr, TCB_ERR_INTERNAL, "surface of frame %d: a chart id or (u, v) outside its range",
                        frame);
    if (!faces_valid(m))
        return tcb_fail(merr, TCB_ERR_INTERNAL,
                        "surface of frame %d: a face names a vertex out of range or spans two charts", frame);
    return TCB_OK;
}

/* The edge graph of a triangle mesh (tcb/geodesic.h): CSR adjacency built
 * once per topology, its connected components, and a frame's edge lengths. */
#include "tcb/geodesic.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

static int check_faces(const int32_t *faces, int nf, int nv, tcb_error *err)
{
    if (nv < 1) return tcb_fail(err, TCB_ERR_INPUT, "edge graph: no vertices");
    if (nf < 0) return tcb_fail(err, TCB_ERR_INPUT, "edge graph: negative face count %d", nf);
    for (int f = 0; f < nf; f++)
        for (int c = 0; c < 3; c++)
            if (faces[3 * (size_t)f + c] < 0 || faces[3 * (size_t)f + c] >= nv)
                return tcb_fail(err, TCB_ERR_INPUT, "edge graph: face %d names vertex %d of %d", f,
                                (int)faces[3 * (size_t)f + c], nv);
    return TCB_OK;
}

/* Every side of every face in both directions into rows of up to
 * 2·(faces at v) entries, then each row sorted and its repeats (a side two
 * faces share) dropped, compacting adj in place. */
static void fill_rows(const int32_t *faces, int nf, tcb_edge_graph *g, int32_t *fill)
{
    int nv = g->n_verts;
    for (int f = 0; f < nf; f++)
        for (int c = 0; c < 3; c++) {
            int32_t a = faces[3 * (size_t)f + c], b = faces[3 * (size_t)f + (c + 1) % 3];
            if (a == b) continue;
            g->adj[fill[a]++] = b;
            g->adj[fill[b]++] = a;
        }
    int32_t out = 0;
    for (int v = 0; v < nv; v++) {
        int32_t lo = g->offsets[v], hi = fill[v];
        qsort(g->adj + lo, (size_t)(hi - lo), sizeof *g->adj, cmp_i32);
        g->offsets[v] = out;
        for (int32_t e = lo; e < hi; e++)
            if (e == lo || g->adj[e] != g->adj[e - 1]) g->adj[out++] = g->adj[e];
    }
    g->offsets[nv] = out;
    g->n_edges = out / 2;
}

/* Components by breadth-first search from each unlabelled vertex in
 * ascending order, so the numbering depends on the topology only. */
static void label_components(tcb_edge_graph *g, int32_t *queue)
{
    for (int v = 0; v < g->n_verts; v++) g->component[v] = -1;
    g->n_components = 0;
    for (int s = 0; s < g->n_verts; s++) {
        if (g->component[s] >= 0) continue;
        int head = 0, tail = 0;
        queue[tail++] = s;
        g->component[s] = g->n_components;
        while (head < tail) {
            int32_t v = queue[head++];
            for (int32_t e = g->offsets[v]; e < g->offsets[v + 1]; e++)
                if (g->component[g->adj[e]] < 0) {
                    g->component[g->adj[e]] = g->n_components;
                    queue[tail++] = g->adj[e];
                }
        }
        g->n_components++;
    }
}

int tcb_edge_graph_build(const int32_t *faces, int nf, int nv, tcb_edge_graph *out,
                         tcb_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_faces(faces, nf, nv, err);
    if (rc) return rc;
    if ((size_t)nf * 6 > INT32_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "edge graph: %d faces are too many", nf);
    out->n_verts = nv;
    out->offsets = calloc((size_t)nv + 1, sizeof *out->offsets);
    out->adj = malloc(((size_t)nf * 6 + 1) * sizeof *out->adj);
    out->component = malloc((size_t)nv * sizeof *out->component);
    int32_t *scratch = malloc((size_t)nv * sizeof *scratch); /* row fill, then BFS queue */
    if (!out->offsets || !out->adj || !out->component || !scratch) {
        free(scratch);
        tcb_edge_graph_free(out);
        return tcb_fail(err, TCB_ERR_NOMEM, "edge graph: out of memory for %d faces", nf);
    }
    /* Row v starts after the 2·(face corners at v) slots of the rows before it. */
    for (int f = 0; f < nf; f++)
        for (int c = 0; c < 3; c++) out->offsets[faces[3 * (size_t)f + c] + 1] += 2;
    for (int v = 0; v < nv; v++) out->offsets[v + 1] += out->offsets[v];
    memcpy(scratch, out->offsets, (size_t)nv * sizeof *scratch);
    fill_rows(faces, nf, out, scratch);
    label_components(out, scratch);
    free(scratch);
    /* Give back the room the repeated sides took (half of it on a closed
     * mesh); a failed shrink keeps the larger block, which is as good. */
    int32_t *fit = realloc(out->adj, ((size_t)2 * out->n_edges + 1) * sizeof *fit);
    if (fit) out->adj = fit;
    return TCB_OK;
}

void tcb_edge_graph_free(tcb_edge_graph *g)
{
    if (!g) return;
    free(g->offsets);
    free(g->adj);
    free(g->component);
    memset(g, 0, sizeof *g);
}

void tcb_edge_graph_lengths(const tcb_edge_graph *g, const float *verts, double *w)
{
    for (int a = 0; a < g->n_verts; a++) {
        const float *p = verts + 3 * (size_t)a;
        for (int32_t e = g->offsets[a]; e < g->offsets[a + 1]; e++) {
            const float *q = verts + 3 * (size_t)g->adj[e];
            double dx = (double)p[0] - q[0], dy = (double)p[1] - q[1], dz = (double)p[2] - q[2];
            w[e] = sqrt(dx * dx + dy * dy + dz * dz);
        }
    }
}

/* Normal-compatible k-NN: a kd-tree over the points whose every node also
 * bounds its points' normals, so that a search skips a subtree whose normals
 * all face away from the query's as it skips one that lies too far.
 *
 * Written here because no kept library prunes a nearest-neighbour search by
 * a second attribute: FLANN can only filter candidates after fetching them.
 * tcbench did that until 2026-12 (a block of plain nearest candidates,
 * widened 4× until k compatible ones were in it). Between frames far apart —
 * crane's random pairs — many points' nearest neighbours lie on the far side
 * of a thin part, the blocks grew to hundreds and FLANN's result set,
 * O(block) per insertion, took most of a registration (perf: 60 % of a
 * crane cell in FLANN's search and result sets). Here a query costs about
 * what a plain one does, however the clouds are posed.
 *
 * The tree splits at the median of the widest axis (ties by index, so the
 * tree depends on the input alone) down to LEAF points. Its bounds are
 * exact in float arithmetic (below), so the results are those of an
 * exhaustive scan, exact ties included. */
#include "methods/nricp/knn_compat.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LEAF 16

typedef struct node {
    float lo[3], hi[3];   /* bounds of the points' positions */
    float nlo[3], nhi[3]; /* bounds of their normals */
    int begin, end;       /* its points: [begin, end) of the index's order */
    int32_t min_id;       /* their lowest caller's index (an exact tie goes to the lower) */
    int left, right;      /* children; -1 for a leaf */
    int axis;             /* the split: left's points ≤ split ≤ right's along axis as */
    float split;          /* built; after a move, only which child a search tries first */
} node;

/* The points in the tree's order, one array per coordinate so that a
 * leaf's scan runs in vector lanes. */
struct nricp_compat_index {
    int n, n_nodes;
    float *x, *y, *z, *nx, *ny, *nz; /* [n] each, one allocation */
    int32_t *id;                      /* [n]: the caller's index of each */
    node *nodes;                      /* nodes[0] is the root */
};

/* ---- build ------------------------------------------------------------------ */

static int count_nodes(int n) { return n <= LEAF ? 1 : 1 + count_nodes(n / 2) + count_nodes(n - n / 2); }

static inline int key_less(const float *p, int axis, int32_t a, int32_t b)
{
    float x = p[3 * (size_t)a + axis], y = p[3 * (size_t)b + axis];
    return x < y || (x == y && a < b);
}

/* Reorder v[0..n) so that v[nth] holds the element of that rank by
 * (coordinate, index) and no smaller one follows it nor larger precedes. */
static void select_nth(const float *p, int axis, int32_t *v, int n, int nth)
{
    int lo = 0, hi = n - 1;
    while (hi > lo) {
        int32_t a = v[lo], b = v[lo + (hi - lo) / 2], c = v[hi], pivot;
        if (key_less(p, axis, a, b)) pivot = key_less(p, axis, b, c) ? b : key_less(p, axis, a, c) ? c : a;
        else pivot = key_less(p, axis, a, c) ? a : key_less(p, axis, b, c) ? c : b;
        int i = lo, j = hi;
        while (i <= j) {
            while (key_less(p, axis, v[i], pivot)) i++;
            while (key_less(p, axis, pivot, v[j])) j--;
            if (i <= j) {
                int32_t t = v[i];
                v[i++] = v[j], v[j--] = t;
            }
        }
        if (nth <= j) hi = j;
        else if (nth >= i) lo = i;
        else return;
    }
}

static void bound(const float *x, const int32_t *ids, int n, float lo[3], float hi[3])
{
    for (int c = 0; c < 3; c++) lo[c] = hi[c] = x[3 * (size_t)ids[0] + c];
    for (int i = 1; i < n; i++)
        for (int c = 0; c < 3; c++) {
            float v = x[3 * (size_t)ids[i] + c];
            lo[c] = v < lo[c] ? v : lo[c];
            hi[c] = v > hi[c] ? v : hi[c];
        }
}

/* Node for ids[begin, end) (the caller's indices), built depth first. */
static int build_node(nricp_compat_index *ix, const float *pts, const float *nrm, int32_t *ids, int begin,
                      int end)
{
    int self = ix->n_nodes++;
    node *nd = &ix->nodes[self];
    *nd = (node){.begin = begin, .end = end, .left = -1, .right = -1};
    bound(pts, ids + begin, end - begin, nd->lo, nd->hi);
    bound(nrm, ids + begin, end - begin, nd->nlo, nd->nhi);
    nd->min_id = ids[begin];
    for (int i = begin + 1; i < end; i++) nd->min_id = ids[i] < nd->min_id ? ids[i] : nd->min_id;
    if (end - begin <= LEAF) return self;
    int axis = 0;
    for (int c = 1; c < 3; c++)
        if (nd->hi[c] - nd->lo[c] > nd->hi[axis] - nd->lo[axis]) axis = c;
    int half = (end - begin) / 2;
    select_nth(pts, axis, ids + begin, end - begin, half);
    nd->axis = axis, nd->split = pts[3 * (size_t)ids[begin + half] + axis];
    int left = build_node(ix, pts, nrm, ids, begin, begin + half);
    int right = build_node(ix, pts, nrm, ids, begin + half, end);
    ix->nodes[self].left = left, ix->nodes[self].right = right;
    return self;
}

int nricp_compat_build(const float *pts, const float *nrm, int n, nricp_compat_index **out, tcb_error *err)
{
    *out = NULL;
    if (n < 1) return tcb_fail(err, TCB_ERR_INTERNAL, "nricp: an index over %d points", n);
    nricp_compat_index *ix = calloc(1, sizeof *ix);
    if (!ix) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    ix->n = n;
    ix->x = malloc((size_t)n * 6 * sizeof *ix->x);
    ix->id = malloc((size_t)n * sizeof *ix->id);
    ix->nodes = malloc((size_t)count_nodes(n) * sizeof *ix->nodes);
    if (!ix->x || !ix->id || !ix->nodes) {
        nricp_compat_free(ix);
        return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for an index of %d points", n);
    }
    for (int i = 0; i < n; i++) ix->id[i] = i;
    build_node(ix, pts, nrm, ix->id, 0, n);
    float *col[6];
    for (int c = 0; c < 6; c++) col[c] = ix->x + (size_t)c * n;
    ix->y = col[1], ix->z = col[2], ix->nx = col[3], ix->ny = col[4], ix->nz = col[5];
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            col[c][i] = pts[3 * (size_t)ix->id[i] + c];
            col[3 + c][i] = nrm[3 * (size_t)ix->id[i] + c];
        }
    *out = ix;
    return TCB_OK;
}

/* A node's position box from its points (a leaf) or its children. */
static void refit_node(nricp_compat_index *ix, node *nd)
{
    if (nd->left >= 0) {
        const node *a = &ix->nodes[nd->left], *b = &ix->nodes[nd->right];
        for (int c = 0; c < 3; c++) {
            nd->lo[c] = a->lo[c] < b->lo[c] ? a->lo[c] : b->lo[c];
            nd->hi[c] = a->hi[c] > b->hi[c] ? a->hi[c] : b->hi[c];
        }
        return;
    }
    const float *col[3] = {ix->x, ix->y, ix->z};
    for (int c = 0; c < 3; c++) {
        float lo = col[c][nd->begin], hi = lo;
        for (int i = nd->begin + 1; i < nd->end; i++) {
            lo = col[c][i] < lo ? col[c][i] : lo;
            hi = col[c][i] > hi ? col[c][i] : hi;
        }
        nd->lo[c] = lo, nd->hi[c] = hi;
    }
}

void nricp_compat_move(nricp_compat_index *ix, const float *pts)
{
    for (int i = 0; i < ix->n; i++) {
        const float *p = pts + 3 * (size_t)ix->id[i];
        ix->x[i] = p[0], ix->y[i] = p[1], ix->z[i] = p[2];
    }
    /* nodes are numbered parent before children: children are refitted first */
    for (int at = ix->n_nodes - 1; at >= 0; at--) refit_node(ix, &ix->nodes[at]);
}

void nricp_compat_free(nricp_compat_index *ix)
{
    if (!ix) return;
    free(ix->x), free(ix->id), free(ix->nodes);
    free(ix);
}

/* ---- search ------------------------------------------------------------------ */

typedef struct search {
    const float *p, *n; /* the query */
    int k, found;
    int32_t *idx;       /* [k] by (d², index) */
    float *d2;          /* [k] */
} search;

/* Both tests below are exact bounds in float arithmetic, not estimates:
 * they evaluate the same expressions, in the same order, as the point's own
 * test (the dot n · m summed x, y, z; d² = (dx² + dy²) + dz²) on the box's
 * ends, and rounding is monotone, so no point of the box can do better than
 * its bound — a search prunes only what an exhaustive scan would reject. */

/* May a point of the node face the query's way? The largest n · m over
 * the node's normal box. */
static int normals_may_fit(const node *nd, const search *s)
{
    float best = 0;
    for (int c = 0; c < 3; c++) {
        float a = s->n[c] * nd->nlo[c], b = s->n[c] * nd->nhi[c];
        best += a > b ? a : b;
    }
    return best >= 0.0f;
}

/* The smallest d² from p to a point of the node's box (0 inside). */
static float box_gap(const node *nd, const float *p)
{
    float d = 0;
    for (int c = 0; c < 3; c++) {
        float below = nd->lo[c] - p[c], above = p[c] - nd->hi[c];
        float g = below > 0 ? below : above > 0 ? above : 0;
        d += g * g;
    }
    return d;
}

/* May a point of the node, at d² ≥ gap, displace the current k-th? At an
 * exact tie only one of a lower index. */
static int near_enough(const node *nd, float gap, const search *s)
{
    if (s->found < s->k) return 1;
    float worst = s->d2[s->k - 1];
    return gap < worst || (gap == worst && nd->min_id < s->idx[s->k - 1]);
}

/* Insert (d2, id) into the sorted k best when it belongs there. */
static void offer(search *s, float d2, int32_t id)
{
    int at, last = s->k - 1;
    if (s->found < s->k) at = s->found++;
    else if (d2 < s->d2[last] || (d2 == s->d2[last] && id < s->idx[last])) at = last;
    else return;
    while (at > 0 && (d2 < s->d2[at - 1] || (d2 == s->d2[at - 1] && id < s->idx[at - 1]))) {
        s->d2[at] = s->d2[at - 1], s->idx[at] = s->idx[at - 1];
        at--;
    }
    s->d2[at] = d2, s->idx[at] = id;
}

/* The leaf's d² in lanes (an incompatible point's is +inf: the dot's sum
 * in x, y, z order, as the contract says), then the offers in order. */
static void scan_leaf(const nricp_compat_index *ix, const node *nd, search *s)
{
    float d2[LEAF];
    int m = nd->end - nd->begin;
    const float *x = ix->x + nd->begin, *y = ix->y + nd->begin, *z = ix->z + nd->begin;
    const float *nx = ix->nx + nd->begin, *ny = ix->ny + nd->begin, *nz = ix->nz + nd->begin;
    for (int i = 0; i < m; i++) {
        float dot = s->n[0] * nx[i] + s->n[1] * ny[i] + s->n[2] * nz[i];
        float dx = s->p[0] - x[i], dy = s->p[1] - y[i], dz = s->p[2] - z[i];
        float d = dx * dx + dy * dy + dz * dz;
        d2[i] = dot >= 0.0f ? d : INFINITY;
    }
    for (int i = 0; i < m; i++)
        if (d2[i] != INFINITY) offer(s, d2[i], ix->id[nd->begin + i]);
}

/* Depth first, the child on the query's side of the split first. gap is
 * a lower bound of the node's box_gap: the near child inherits its
 * parent's (it is rarely pruned), the far one gets its own. */
static void visit(const nricp_compat_index *ix, int at, float gap, search *s)
{
    const node *nd = &ix->nodes[at];
    if (!near_enough(nd, gap, s) || !normals_may_fit(nd, s)) return;
    if (nd->left < 0) {
        scan_leaf(ix, nd, s);
        return;
    }
    int near = s->p[nd->axis] < nd->split ? nd->left : nd->right, far = near == nd->left ? nd->right : nd->left;
    visit(ix, near, gap, s);
    const node *f = &ix->nodes[far];
    visit(ix, far, box_gap(f, s->p), s);
}

int nricp_knn_compat(const nricp_compat_index *ix, const float *qp, const float *qn, int nq, int k,
                     int32_t *idx, float *d2, int *cnt, tcb_error *err)
{
    if (k < 1) return tcb_fail(err, TCB_ERR_INTERNAL, "nricp: k-NN with k = %d", k);
    float *dist = malloc((size_t)k * sizeof *dist);
    if (!dist) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    for (int q = 0; q < nq; q++) {
        const float *n = qn + 3 * (size_t)q;
        search s = {qp + 3 * (size_t)q, n, k, 0, idx + (size_t)q * k, dist};
        visit(ix, 0, box_gap(&ix->nodes[0], s.p), &s);
        cnt[q] = s.found;
        for (int a = s.found; a < k; a++) s.idx[a] = -1, dist[a] = 0.0f;
        if (d2) memcpy(d2 + (size_t)q * k, dist, (size_t)k * sizeof *dist);
    }
    free(dist);
    return TCB_OK;
}

/* The holes left in the prepared mesh closed: each boundary loop whose extent is under
 * [output] max_hole_mm (the diagonal of its bounding box, as mesh-compare measures a hole) is
 * fanned from a new vertex at its centre.
 *
 * A boundary edge is an edge of one kept triangle only. They are found with a set of open edges
 * toggled triangle by triangle (an edge met a second time is inner and leaves the set): marching
 * cubes gives its triangles slab by slab along z, so the set holds one slab's front and the
 * boundaries, not the whole mesh, and fits in the space fusion_integrate's pixel weights use
 * while views are fused (struct fusion_volume's open_edge). The boundary edges, directed as
 * their triangle runs, are then sorted by their first vertex and walked into loops. */
#include "fusion.h"
#include "mem.h"

#include <errno.h>
#include <math.h>
#include <string.h>

#define SLOTS (sizeof(((struct fusion_volume *)0)->open_edge) / sizeof(uint64_t))
#define USED (1ull << 63) /* a boundary edge already walked */

static uint64_t edge_key(uint64_t e) /* directed edge -> its undirected key */
{
    uint64_t a = (e >> 32) & 0x7FFFFFFFu, b = e & 0xFFFFFFFFu;
    return a < b ? a << 32 | b : b << 32 | a;
}

static size_t home_slot(uint64_t key)
{
    key ^= key >> 33; /* the finaliser of MurmurHash3: vertex numbers spread over the slots */
    key *= 0xff51afd7ed558ccdull;
    key ^= key >> 33;
    return (size_t)(key % SLOTS);
}

/* The edge a -> b into the set of open edges, or out of it if its twin is there (linear
 * probing, deletion by shifting back the entries after it: Knuth 6.4, algorithm R).
 * @retval 0 @retval -ENOSPC the set is half full */
static int toggle_edge(struct fusion_volume *vol, uint32_t *open, uint32_t a, uint32_t b)
{
    uint64_t *t = vol->open_edge, e = (uint64_t)a << 32 | b, key = edge_key(e);
    size_t i = home_slot(key);
    while (t[i] != 0 && edge_key(t[i]) != key)
        i = (i + 1) % SLOTS;
    if (t[i] == 0) {
        if (*open >= SLOTS / 2)
            return -ENOSPC;
        t[i] = e;
        (*open)++;
        return 0;
    }
    for (size_t j = i;;) { /* remove slot i, moving back what would no longer be found */
        j = (j + 1) % SLOTS;
        if (t[j] == 0)
            break;
        size_t k = home_slot(edge_key(t[j]));
        if (i <= j ? (i < k && k <= j) : (i < k || k <= j))
            continue; /* still reachable from its home */
        t[i] = t[j];
        i = j;
    }
    t[i] = 0;
    (*open)--;
    return 0;
}

/* Heapsort (no allocation, bounded time) of @p n edges by their first vertex, then second. */
static void sift_down(uint64_t *e, size_t root, size_t n)
{
    for (size_t child; (child = 2 * root + 1) < n; root = child) {
        if (child + 1 < n && e[child + 1] > e[child])
            child++;
        if (e[root] >= e[child])
            return;
        uint64_t t = e[root];
        e[root] = e[child];
        e[child] = t;
    }
}

static void sort_edges(uint64_t *e, size_t n)
{
    for (size_t i = n / 2; i-- > 0;)
        sift_down(e, i, n);
    for (size_t end = n; end-- > 1;) {
        uint64_t t = e[0];
        e[0] = e[end];
        e[end] = t;
        sift_down(e, 0, end);
    }
}

/* An unwalked boundary edge leaving vertex @p v. @retval its index @retval n none */
static size_t edge_from(const uint64_t *e, size_t n, uint32_t v)
{
    size_t lo = 0, hi = n;
    while (lo < hi) { /* the first edge whose first vertex is >= v */
        size_t mid = lo + (hi - lo) / 2;
        if (((e[mid] >> 32) & 0x7FFFFFFFu) < v)
            lo = mid + 1;
        else
            hi = mid;
    }
    for (; lo < n && ((e[lo] >> 32) & 0x7FFFFFFFu) == v; lo++)
        if (!(e[lo] & USED))
            return lo;
    return n;
}

/* The diagonal of the bounding box of the @p len vertices of @p loop (mm). */
static double loop_extent(const struct fusion_volume *vol, const uint32_t *loop, uint32_t len)
{
    float lo[3], hi[3];
    for (uint32_t k = 0; k < len; k++)
        for (int c = 0; c < 3; c++) {
            float x = vol->mesh_pos[3 * (size_t)loop[k] + c];
            lo[c] = k == 0 || x < lo[c] ? x : lo[c];
            hi[c] = k == 0 || x > hi[c] ? x : hi[c];
        }
    return sqrt((double)(hi[0] - lo[0]) * (hi[0] - lo[0]) +
                (double)(hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (double)(hi[2] - lo[2]) * (hi[2] - lo[2]));
}

/* Close the simple loop @p loop: a vertex at its centre (mean position, mean normal, the
 * mean colour of its coloured vertices) and a triangle from each of its edges to it, wound
 * against the edge's own triangle so that the mesh stays consistently oriented.
 * @retval 0 @retval -E2BIG the tables are full */
static int fan_loop(struct fusion_volume *vol, const uint32_t *loop, uint32_t len)
{
    struct mesh_summary *s = &vol->mp.s;
    if (s->vertices >= MESH_MAX_VERTICES || s->triangles + len > MESH_MAX_TRIANGLES)
        return -E2BIG;
    uint32_t c = s->vertices;
    double pos[3] = {0, 0, 0}, nrm[3] = {0, 0, 0}, rgb[3] = {0, 0, 0};
    uint32_t coloured = 0;
    for (uint32_t k = 0; k < len; k++) {
        uint32_t v = loop[k];
        for (int i = 0; i < 3; i++) {
            pos[i] += vol->mesh_pos[3 * (size_t)v + i] / (double)len;
            nrm[i] += vol->mesh_nrm[3 * (size_t)v + i];
            rgb[i] += vol->mesh_coloured[v] ? vol->mesh_rgb[3 * (size_t)v + i] : 0.0;
        }
        coloured += vol->mesh_coloured[v] != 0;
    }
    double nl = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    for (int i = 0; i < 3; i++) {
        vol->mesh_pos[3 * (size_t)c + i] = (float)pos[i];
        vol->mesh_nrm[3 * (size_t)c + i] = nl > 0.0 ? (float)(nrm[i] / nl) : 0.0f;
        vol->mesh_rgb[3 * (size_t)c + i] = coloured > 0 ? (uint16_t)lround(rgb[i] / coloured)
                                                        : vol->mesh_rgb[3 * (size_t)loop[0] + i];
    }
    vol->mesh_coloured[c] = coloured > 0 || vol->mesh_coloured[loop[0]];
    vol->mesh_index[c] = s->kept_vertices++;
    s->vertices++;
    for (uint32_t k = 0; k < len; k++) {
        uint32_t *tri = &vol->mesh_tri[3 * (size_t)s->triangles++];
        tri[0] = loop[(k + 1) % len]; /* the edge a -> b runs b -> a here */
        tri[1] = loop[k];
        tri[2] = c;
    }
    s->kept_triangles += len;
    return 0;
}

/* The simple loop @p loop closed when narrower than @p max_hole_mm, else counted as left. */
static int close_loop(struct fusion_volume *vol, const uint32_t *loop, uint32_t len,
                      double max_hole_mm, struct mesh_hole_report *out)
{
    if (len < 3 || loop_extent(vol, loop, len) >= max_hole_mm) {
        out->left++;
        return 0;
    }
    int rc = fan_loop(vol, loop, len);
    out->filled += rc == 0;
    return rc;
}

/* Walk the boundary edges from @p first until the walk comes back to where it started, closing
 * each simple loop on the way: a walk that meets one of its own vertices again (two holes
 * touching at a vertex) has gone round a simple loop, which is closed on its own and cut from
 * the walk, so that no edge to a fan's centre is shared by two fans. A walk that stops (an edge
 * of three triangles) or outgrows MESH_HOLE_MAX_LOOP is left open. */
static int walk_loops(struct fusion_volume *vol, uint64_t *e, size_t n, size_t first,
                      double max_hole_mm, struct mesh_hole_report *out)
{
    uint32_t *loop = vol->hole_loop, len = 0;
    loop[len++] = (uint32_t)(e[first] >> 32) & 0x7FFFFFFFu;
    for (size_t i = first; i < n;) {
        e[i] |= USED;
        uint32_t to = (uint32_t)e[i], at = len;
        for (uint32_t k = 0; k < len; k++)
            if (loop[k] == to)
                at = k;
        if (at < len) { /* round a simple loop: loop[at] .. loop[len - 1] */
            int rc = close_loop(vol, &loop[at], len - at, max_hole_mm, out);
            if (rc != 0)
                return rc;
            len = at + 1; /* the walk goes on from loop[at] */
            if (at == 0 && edge_from(e, n, to) == n)
                return 0; /* back at the start, nothing more from here */
        } else if (len == MESH_HOLE_MAX_LOOP) {
            break;
        } else {
            loop[len++] = to;
        }
        i = edge_from(e, n, to);
    }
    out->left += len > 1; /* a walk that did not close */
    return 0;
}

int fusion_mesh_fill_holes(struct fusion_volume *vol, double max_hole_mm,
                           struct mesh_hole_report *out)
{
    memset(out, 0, sizeof(*out));
    if (!vol->mp.prepared)
        return -EINVAL;
    if (!vol->mp.fits || max_hole_mm <= 0.0)
        return 0; /* nothing to do, or a mesh streamed from marching cubes: left as it is */
    uint32_t open = 0, triangles = vol->mp.s.triangles;
    mem_fill(vol->open_edge, 0, sizeof(vol->open_edge));
    for (uint32_t t = 0; t < triangles; t++) {
        const uint32_t *tri = &vol->mesh_tri[3 * (size_t)t];
        if (vol->mesh_index[tri[0]] == MESH_DROPPED)
            continue;
        for (int k = 0; k < 3; k++) {
            uint32_t a = tri[k], b = tri[(k + 1) % 3];
            int rc = a != b ? toggle_edge(vol, &open, a, b) : 0;
            if (rc != 0)
                return rc;
        }
    }
    size_t n = 0;
    for (size_t i = 0; i < SLOTS && n < open; i++)
        if (vol->open_edge[i] != 0)
            vol->open_edge[n++] = vol->open_edge[i];
    sort_edges(vol->open_edge, n);
    out->boundary_edges = (uint32_t)n;
    for (size_t i = 0; i < n; i++) {
        if (vol->open_edge[i] & USED)
            continue;
        int rc = walk_loops(vol, vol->open_edge, n, i, max_hole_mm, out);
        if (rc != 0)
            return rc;
    }
    return 0;
}

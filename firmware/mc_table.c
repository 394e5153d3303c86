/* Marching-cubes cases from first principles: on each cube face, marching squares joins the edges
 * where the sign changes (an ambiguous face always separates its inside corners, a rule that
 * depends on the face alone, so two cells sharing a face agree and the surface is watertight);
 * the segments of the six faces close into loops, and each loop is fanned into triangles facing
 * from inside to outside. */
#include "mc_table.h"

#include "vec3.h"

const uint8_t mc_edge_corner[12][2] = {
    {0, 1}, {2, 3}, {4, 5}, {6, 7}, /* along x */
    {0, 2}, {1, 3}, {4, 6}, {5, 7}, /* along y */
    {0, 4}, {1, 5}, {2, 6}, {3, 7}, /* along z */
};

static struct mc_case cases[256];
static int built;

static int edge_of(unsigned a, unsigned b)
{
    for (int e = 0; e < 12; e++)
        if ((mc_edge_corner[e][0] == a && mc_edge_corner[e][1] == b) ||
            (mc_edge_corner[e][0] == b && mc_edge_corner[e][1] == a))
            return e;
    return -1;
}

static vec3 corner_pos(unsigned c)
{
    return v3(c & 1u, (c >> 1) & 1u, (c >> 2) & 1u);
}

static vec3 edge_mid(int e)
{
    return v3_scale(v3_add(corner_pos(mc_edge_corner[e][0]), corner_pos(mc_edge_corner[e][1])),
                    0.5);
}

/* The four corners of face (axis, side) in cyclic order. */
static void face_corners(int axis, int side, unsigned q[4])
{
    int b = (axis + 1) % 3, c = (axis + 2) % 3;
    static const int cyc[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 4; k++)
        q[k] = (unsigned)((side << axis) | (cyc[k][0] << b) | (cyc[k][1] << c));
}

/* Add segment a-b to the link lists of the crossing edges. */
static void link(int nb[12][2], int a, int b)
{
    nb[a][nb[a][0] < 0 ? 0 : 1] = b;
    nb[b][nb[b][0] < 0 ? 0 : 1] = a;
}

static void build_case(unsigned m)
{
    int nb[12][2];
    for (int e = 0; e < 12; e++)
        nb[e][0] = nb[e][1] = -1;
    for (int axis = 0; axis < 3; axis++) {
        for (int side = 0; side < 2; side++) {
            unsigned q[4];
            face_corners(axis, side, q);
            int in[4], cross[4];
            for (int k = 0; k < 4; k++)
                in[k] = (m >> q[k]) & 1u;
            for (int k = 0; k < 4; k++) /* cross[k]: edge from corner k to corner k+1 */
                cross[k] = in[k] != in[(k + 1) % 4] ? edge_of(q[k], q[(k + 1) % 4]) : -1;
            int n = (cross[0] >= 0) + (cross[1] >= 0) + (cross[2] >= 0) + (cross[3] >= 0);
            if (n == 2) {
                int a = -1, b = -1;
                for (int k = 0; k < 4; k++) {
                    if (cross[k] >= 0 && a < 0)
                        a = cross[k];
                    else if (cross[k] >= 0)
                        b = cross[k];
                }
                link(nb, a, b);
            } else if (n == 4) {
                /* cut off each inside corner: corner k lies between edges k-1 and k */
                for (int k = 0; k < 4; k++)
                    if (in[k])
                        link(nb, cross[(k + 3) % 4], cross[k]);
            }
        }
    }
    struct mc_case *out = &cases[m];
    out->tri_count = 0;
    int used[12] = {0};
    for (int start = 0; start < 12; start++) {
        if (nb[start][0] < 0 || used[start])
            continue;
        int loop[12], len = 0, prev = -1, cur = start;
        while (!used[cur]) { /* walk the loop */
            used[cur] = 1;
            loop[len++] = cur;
            int next = nb[cur][0] != prev ? nb[cur][0] : nb[cur][1];
            prev = cur;
            cur = next;
        }
        /* Outward: from each crossing edge's inside corner to its outside corner. */
        vec3 out_dir = v3(0, 0, 0), n = v3(0, 0, 0);
        for (int k = 0; k < len; k++) {
            unsigned c0 = mc_edge_corner[loop[k]][0], c1 = mc_edge_corner[loop[k]][1];
            vec3 d = v3_sub(corner_pos(c1), corner_pos(c0));
            out_dir = v3_add(out_dir, ((m >> c0) & 1u) ? d : v3_scale(d, -1.0));
            n = v3_add(n, v3_cross(edge_mid(loop[k]), edge_mid(loop[(k + 1) % len])));
        }
        int flip = v3_dot(n, out_dir) < 0.0;
        for (int k = 1; k + 1 < len && out->tri_count < MC_MAX_TRIS; k++) {
            uint8_t *t = out->edge[out->tri_count++];
            t[0] = (uint8_t)loop[0];
            t[1] = (uint8_t)loop[flip ? k + 1 : k];
            t[2] = (uint8_t)loop[flip ? k : k + 1];
        }
    }
}

void mc_table_build(void)
{
    if (built)
        return;
    for (unsigned m = 0; m < 256; m++)
        build_case(m);
    built = 1;
}

const struct mc_case *mc_table_case(unsigned pattern)
{
    return &cases[pattern & 0xFFu];
}

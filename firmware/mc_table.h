/* Marching-cubes case table, generated at start-up from the cube's faces (no typed-in table). */
#ifndef MC_TABLE_H
#define MC_TABLE_H

#include <stdint.h>

/* Corner i of a cell sits at (i & 1, (i >> 1) & 1, (i >> 2) & 1). Edge e joins the two corners
 * of mc_edge_corner[e]; edges 0-3 run along x, 4-7 along y, 8-11 along z. */
extern const uint8_t mc_edge_corner[12][2];

#define MC_MAX_TRIS 12

/** Triangles (edge triples, outward = towards positive distance) of each of the 256 inside/
 *  outside patterns (bit i: corner i inside, i.e. negative). */
struct mc_case {
    uint8_t tri_count;
    uint8_t edge[MC_MAX_TRIS][3];
};

/** Fill the table (idempotent; no allocation). */
void mc_table_build(void);
/** The case of a pattern; mc_table_build must have run. */
const struct mc_case *mc_table_case(unsigned pattern);

#endif

/* Union-find over an array of parents (index i's parent; a root is its own): the mesh's pieces
 * (mesh_io.c) and the texture's charts (atlas.c). */
#ifndef UNIONFIND_H
#define UNIONFIND_H

#include <stdint.h>

/** The root of @p x's set, halving the path on the way. */
static inline uint32_t uf_root(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

/** Join the sets of @p a and @p b: the larger root under the smaller, so that a root is its set's
 *  smallest index and the result does not depend on the order of the joins. */
static inline void uf_join(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = uf_root(parent, a);
    b = uf_root(parent, b);
    if (a != b)
        parent[a > b ? a : b] = a < b ? a : b;
}

#endif

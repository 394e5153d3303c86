/* build/mesh-compare RESULT.ply TRUTH.ply [SCAN_DIR]: how close a scanned mesh is to the true
 * surface. Both surfaces are sampled uniformly by area (deterministic); each sample's distance to
 * the other mesh is exact (closest point on the nearest triangle, through a BVH). With SCAN_DIR
 * (its calibration.ini and config.ini) it also reports the observable part of the true surface:
 * what some view's camera and projector both reach, unoccluded, at under 75 degrees. With
 * --align the result is first moved rigidly onto the truth (the scan's frame is its first
 * view's, which a table that missed its angle turns). */
#define _POSIX_C_SOURCE 200809L
#include "config.h"
#include "frames.h"
#include "mesh_compare.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    int align = argc > 1 && strcmp(argv[1], "--align") == 0;
    argc -= align;
    argv += align;
    if (argc != 3 && argc != 4) {
        fprintf(stderr, "usage: mesh-compare [--align] RESULT.ply TRUTH.ply [SCAN_DIR]\n");
        return 2;
    }
    struct mesh_comparison r;
    struct mesh_visibility vis;
    char err[512];
    if (argc == 4 && mesh_visibility_from_scan(argv[3], &vis, err, sizeof(err)) != 0) {
        fprintf(stderr, "mesh-compare: %s\n", err);
        return 1;
    }
    if (mesh_compare_files(argv[1], argv[2], 200000, argc == 4 ? &vis : NULL, align, &r, err,
                           sizeof(err)) != 0) {
        fprintf(stderr, "mesh-compare: %s\n", err);
        return 1;
    }
    mesh_compare_print(&r, stdout);
    return 0;
}

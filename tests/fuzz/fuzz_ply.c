/* Fuzz target: the PLY reader of the simulator (object meshes, clouds read back by the tests). */
#define _GNU_SOURCE
#include "fuzz_input.h"

#include "sim_mesh.h"

#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    struct sim_mesh m;
    char err[256] = "";
    const char *path = fuzz_path(data, size);
    int rc = sim_mesh_load_ply(&m, path, err, sizeof(err));
    FUZZ_EXPECT(rc <= 0);
    if (rc == 0) {
        for (uint32_t t = 0; t < m.tri_count; t++) /* every face must index a vertex */
            for (int k = 0; k < 3; k++)
                FUZZ_EXPECT(m.tri[3 * t + k] < m.vert_count);
        sim_mesh_free(&m);
    } else {
        FUZZ_EXPECT(err[0] != '\0');
    }
    rc = sim_mesh_load_ply_points(&m, path, err, sizeof(err));
    FUZZ_EXPECT(rc <= 0);
    if (rc == 0)
        sim_mesh_free(&m);
    return 0;
}

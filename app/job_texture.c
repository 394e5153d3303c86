/* A scan job's colour from the views (job.h): each vertex of the prepared mesh, and its texture
 * atlas, coloured from every view at its registered pose; texture.png with mesh.obj's material. */
#define _POSIX_C_SOURCE 200809L
#include "job.h"

#include "atlas.h"
#include "clock_posix.h"
#include "image_io.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A camera pixel's edge on the object at the turntable's axis: the texture's default texel. */
static double pixel_at_axis_mm(const struct scan_calib *c)
{
    vec3 a = v3_from(c->axis_point_mm);
    return v3_len(a) / c->cam_fx_px;
}

/* View @p v's colour onto the mesh (and its atlas) at its registered pose, its range image read
 * back as the fusion read it. */
static int colour_view(struct job *j, const char *scan_dir, uint32_t v)
{
    struct scan_view view;
    struct scan_view_info info;
    struct frame_xform pose;
    struct reg_view rv;
    int rc = job_view_for_model(j, scan_dir, v, &view, &info);
    if (rc == 0)
        rc = reg_view_pose(j->reg, v, &pose, &rv);
    struct hal_thread cores = scan_cores(&j->hal->thread, &j->cfg->scan);
    if (rc == 0)
        rc = atlas_add_view(j->atlas, j->vol, &cores, j->calib, &pose, &view.maps, &view.range,
                            view.rgb, view.confidence);
    return rc;
}

/* The atlas's texture as texture.png and mesh.mtl; @p png, @p png_len: its encoding. */
static int write_texture(struct job *j, const struct atlas_report *ar, uint8_t **png,
                         size_t *png_len)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), j->out_dir, -1, SCAN_FILE_TEXTURE);
    if (rc == 0) /* once, for texture.png and mesh.glb */
        rc = image_encode_png(j->atlas->texture, ar->width, ar->height, 3, png, png_len);
    if (rc == 0)
        rc = hal_storage_write_file(&j->hal->storage, path, *png, *png_len);
    static const char mtl[] =
        "# turntable colour scanner: the texture of mesh.obj\n"
        "newmtl scan\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nmap_Kd " SCAN_FILE_TEXTURE "\n";
    if (rc == 0)
        rc = scan_dir_path(path, sizeof(path), j->out_dir, -1, SCAN_FILE_MESH_MTL);
    if (rc == 0)
        rc = hal_storage_write_file(&j->hal->storage, path, mtl, sizeof(mtl) - 1);
    return rc;
}

static void no_texture(struct job *j, int rc)
{
    j->hal->log(HAL_LOG_WARN, "no texture: %s%s; the model keeps its vertex colours", strerror(-rc),
                rc == -ENOSPC ? " (more charts than the compiled ATLAS_MAX_CHARTS)" : "");
}

int job_colour_mesh(struct job *j, const char *scan_dir, char *said, size_t said_len, uint8_t **png,
                    size_t *png_len)
{
    *png = NULL;
    *png_len = 0;
    double t0 = clock_posix_thread_cpu_s();
    double texel = j->cfg->texel_mm > 0.0 ? j->cfg->texel_mm : pixel_at_axis_mm(j->calib);
    struct atlas_report ar;
    uint32_t uncoloured = 0, vertices = 0;
    size_t work_bytes;
    void *work = fusion_spend_grid(j->vol, &work_bytes); /* the grid: the mesh is made */
    int textured = j->cfg->texture;
    int rc = atlas_build(j->atlas, j->vol, textured ? texel : 0.0, work, work_bytes, &ar);
    if (rc != 0 && textured) { /* the vertices' colours still */
        no_texture(j, rc);
        textured = 0;
        rc = atlas_build(j->atlas, j->vol, 0.0, work, work_bytes, &ar);
    }
    for (uint32_t v = 0; v < j->views && rc == 0; v++)
        rc = colour_view(j, scan_dir, v);
    if (rc == 0)
        rc = atlas_finish(j->atlas, j->vol, &uncoloured, &vertices);
    if (rc != 0) {
        j->hal->log(HAL_LOG_WARN,
                    "the views' colours not taken onto the mesh: %s; its vertices keep the fusion "
                    "grid's%s",
                    strerror(-rc), textured ? ", and it has no texture" : "");
        return rc;
    }
    int rc_tex = textured ? write_texture(j, &ar, png, png_len) : 0;
    if (rc_tex != 0) {
        free(*png);
        *png = NULL;
        *png_len = 0;
        no_texture(j, rc_tex);
        textured = 0;
    }
    int n = snprintf(said, said_len, "; %u vertices coloured from the views", (unsigned)vertices);
    size_t at = n > 0 && (size_t)n < said_len ? (size_t)n : 0;
    if (textured)
        snprintf(said + at, said_len - at,
                 "; texture %u x %u, %.3f mm a texel%s, %u charts, %.0f%% of it used, %u texels "
                 "no view saw (%.2f s CPU)",
                 (unsigned)ar.width, (unsigned)ar.height, ar.texel_mm,
                 ar.texel_mm > texel * 1.01 ? " (the finest that fits)" : "", (unsigned)ar.charts,
                 100.0 * ar.used_share, (unsigned)uncoloured, clock_posix_thread_cpu_s() - t0);
    else
        snprintf(said + at, said_len - at, " (%.2f s CPU)", clock_posix_thread_cpu_s() - t0);
    return 0;
}

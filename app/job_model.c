/* A scan job's model (job.h): once every view is in, the joint registration, the reflectance
 * fit, each view fused at its registered pose, and the mesh in its four formats. */
#define _POSIX_C_SOURCE 200809L
#include "job.h"

#include "atlas.h"
#include "clock_posix.h"
#include "fusion.h"
#include "gray.h"
#include "reflect.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Results of processed view @p v once the scan is registered: its registration.ini, its point
 * cloud and its part of the fused model, all at the registered pose. @p rv: out, the view's
 * part of the registration. */
static int save_results(struct job *j, uint32_t v, const struct scan_view *view,
                        const struct reg_report *rep, struct reg_view *rv)
{
    char path[HAL_MAX_PATH + 64];
    struct frame_xform pose;
    int rc = reg_view_pose(j->reg, v, &pose, rv);
    if (rc == 0)
        rc = job_write_failed(
            j, v, SCAN_FILE_REGISTRATION,
            scan_dir_write_registration(&j->hal->storage, j->out_dir, v, rep, rv, &pose));
    if (rc == 0)
        rc = scan_dir_path(path, sizeof(path), j->out_dir, (int)v, SCAN_FILE_CLOUD);
    if (rc == 0)
        rc = scan_save_cloud(j->hal, view, &pose, path); /* says what failed itself */
    struct hal_thread cores = scan_cores(&j->hal->thread, &j->cfg->scan);
    if (rc == 0)
        rc = scan_fuse_view(j->vol, &cores, j->calib, view, &pose);
    return rc;
}

/* Few lights leave part of the surface lit in no view that sees it, and its colour is its
 * neighbours': a tenth or more of the model is said, with what colours more of it. Measured on
 * the bunny: one light beside the camera 20% of the vertices in 8 views, 35% in 4; two lights
 * 5% and 10%; four 2% and 1%. */
#define JOB_LITTLE_LIT_SHARE 0.1
static void say_if_little_lit(struct job *j, const struct mesh_summary *ms)
{
    enum colour_method m = j->cfg->scan.colour.method;
    if ((m != COLOUR_MULTI && m != COLOUR_FIT && m != COLOUR_UNIFORM) || ms->kept_vertices == 0 ||
        ms->colour_filled < JOB_LITTLE_LIT_SHARE * ms->kept_vertices)
        return;
    j->hal->log(HAL_LOG_WARN,
                "%.0f%% of the model (%u vertices) was lit by no light in any view that saw it, "
                "and took its neighbours' colour ([lights] count = %u): more lights, on other "
                "sides of the camera and at other heights, or more views colour more of it",
                100.0 * ms->colour_filled / ms->kept_vertices, (unsigned)ms->colour_filled,
                (unsigned)j->calib->light_count);
}

/* The fused model: mesh.ply, mesh.obj, mesh.stl and mesh.glb in the scan directory, without
 * floating fragments, and its texture. */
static int write_model(struct job *j, const char *scan_dir)
{
    static const char *const names[] = {SCAN_FILE_MESH_PLY, SCAN_FILE_MESH_OBJ, SCAN_FILE_MESH_STL,
                                        SCAN_FILE_MESH_GLB};
    int (*const writers[])(struct fusion_volume *, const struct hal_storage *, const char *) = {
        fusion_write_ply, fusion_write_obj, fusion_write_stl, NULL}; /* NULL: glb, below */
    char path[SCAN_DIR_PATH_MAX], detail[HAL_MAX_PATH + 320];
    struct mesh_summary ms;
    uint32_t filled = 0, inside = 0;
    job_progress(j, EV_MESHING, -1, j->views, "marching cubes");
    int rc = j->cfg->watertight ? fusion_fill_holes(j->vol, j->cfg->max_hole_mm, &filled) : 0;
    if (rc == 0 && j->cfg->watertight)
        rc = fusion_close_watertight(j->vol, j->cfg->max_hole_mm, j->cfg->passes == 1, &inside);
    if (rc == 0)
        rc = fusion_mesh_prepare(j->vol, j->cfg->min_fragment_share, &ms);
    int fits = rc == 0;
    struct mesh_hole_report holes = {0, 0, 0};
    if (fits && j->cfg->max_hole_mm > 0.0) {
        rc = fusion_mesh_fill_holes(j->vol, j->cfg->max_hole_mm, &holes);
        if (rc != 0) /* the mesh is whole either way: what was closed stays */
            j->hal->log(HAL_LOG_WARN, "holes left on the mesh unclosed: %s", strerror(-rc));
        rc = fusion_mesh_counts(j->vol, &ms);
    }
    if (rc == -E2BIG)
        j->hal->log(HAL_LOG_WARN,
                    "the mesh has %u vertices, more than MESH_MAX_VERTICES (%u): it is written "
                    "whole, fragments and all, and without mesh.stl and mesh.glb (a larger "
                    "[fusion] voxel_mm "
                    "makes a smaller mesh)",
                    (unsigned)ms.vertices, MESH_MAX_VERTICES);
    else if (rc != 0)
        return rc;
    char texture[256] = "";
    uint8_t *png = NULL; /* the texture, once encoded: texture.png and inside mesh.glb */
    size_t png_len = 0;
    if (fits && rc == 0)
        (void)job_colour_mesh(j, scan_dir, texture, sizeof(texture), &png, &png_len); /* said */
    int textured = png != NULL;
    for (int k = 0; k < 2 && !textured; k++) { /* an earlier model's texture is not this one's */
        static const char *const texture_files[] = {SCAN_FILE_TEXTURE, SCAN_FILE_MESH_MTL};
        int gone = scan_dir_remove(j->out_dir, -1, texture_files[k]);
        if (gone != 0)
            j->hal->log(HAL_LOG_WARN, "cannot remove %s/%s: %s", j->out_dir, texture_files[k],
                        strerror(-gone));
    }
    rc = 0;
    for (size_t k = 0; k < sizeof(names) / sizeof(names[0]) && rc == 0; k++) {
        if (!fits && (writers[k] == fusion_write_stl || writers[k] == NULL))
            continue;
        rc = scan_dir_path(path, sizeof(path), j->out_dir, -1, names[k]);
        if (rc == 0 && textured && writers[k] == fusion_write_obj)
            rc = fusion_write_obj_textured(j->vol, j->atlas, SCAN_FILE_MESH_MTL, &j->hal->storage,
                                           path);
        else if (rc == 0)
            rc = writers[k] != NULL
                     ? writers[k](j->vol, &j->hal->storage, path)
                     : fusion_write_glb_textured(j->vol, &j->hal->storage, path,
                                                 reflect_model(j->pool), /* or matte */
                                                 textured ? j->atlas : NULL, png, png_len);
        if (rc != 0)
            j->hal->log(HAL_LOG_ERROR, "cannot write %s: %s", path, strerror(-rc));
    }
    free(png);
    if (rc != 0)
        return rc;
    char closed[96] = "";
    if (j->cfg->watertight)
        snprintf(closed, sizeof(closed), ", closed watertight, %u unseen voxels made solid",
                 (unsigned)inside);
    char uncoloured[128] = "";
    if (ms.colour_filled > 0 || ms.uncoloured > 0)
        snprintf(uncoloured, sizeof(uncoloured),
                 "; %u vertices no view could colour took their neighbours' colour, %u marked "
                 "grey",
                 (unsigned)ms.colour_filled, (unsigned)ms.uncoloured);
    char mesh_holes[96] = "";
    if (holes.filled > 0)
        snprintf(mesh_holes, sizeof(mesh_holes), ", %u holes on the mesh closed",
                 (unsigned)holes.filled);
    snprintf(detail, sizeof(detail),
             "%u vertices, %u triangles (%u floating fragments of %u pieces left out; %u voxels "
             "filled holes%s%s%s) -> %s/mesh.ply, mesh.obj%s%s",
             (unsigned)ms.kept_vertices, (unsigned)ms.kept_triangles, (unsigned)ms.removed_pieces,
             (unsigned)ms.pieces, (unsigned)filled, mesh_holes, closed, uncoloured, j->out_dir,
             fits ? ", mesh.stl and mesh.glb" : "", texture);
    char fields[192];
    snprintf(fields, sizeof(fields),
             "\"vertices\":%u,\"triangles\":%u,\"pieces_left_out\":%u,\"colour_filled\":%u,"
             "\"uncoloured\":%u",
             (unsigned)ms.kept_vertices, (unsigned)ms.kept_triangles, (unsigned)ms.removed_pieces,
             (unsigned)ms.colour_filled, (unsigned)ms.uncoloured);
    job_progress_with(j, EV_MESH, -1, j->views, fields, detail);
    say_if_little_lit(j, &ms);
    return 0;
}

/* Before the first view: the registration sized for the scan's views. */
int job_begin_model(struct job *j)
{
    struct reg_params p = j->cfg->registration;
    /* uniform is C - Ca under the lights as they fall: shaded like raw colour unless the light
     * is even all round (one or two lights: pairs lost, a scan failed), so compared as raw */
    enum colour_method m = j->cfg->scan.colour.method;
    p.colour_intrinsic = m != COLOUR_NONE && m != COLOUR_UNIFORM; /* else raw: reg.c */
    int rc = reg_begin(j->reg, &p, j->calib, j->views, j->cfg->passes, j->cfg->scan.width,
                       j->cfg->scan.height);
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "registration: %u views exceed the compiled limit %u",
                    (unsigned)j->views, REG_MAX_VIEWS);
    return rc;
}

/* A registration that failed on views nearly empty for an object too dark to decode (which
 * job_say_if_dark said): that, not the calibration, and the exposure to scan again at. @p why:
 * what the registration found. */
static void say_too_dark(struct job *j, const char *why, const char *scan_dir)
{
    j->hal->log(HAL_LOG_ERROR,
                "registration failed: %s: the views hold almost nothing, the object too dark to "
                "decode at exposure_us = %u (the warning above says more). No model was made; "
                "the views are kept in %s. Scan again with the longer exposure",
                why, (unsigned)j->cfg->camera.exposure_us, scan_dir);
}

/* The registration's one quality line, and a refused or failed one said plainly. */
static int report_registration(struct job *j, const struct reg_report *r, double cpu_seconds,
                               const char *scan_dir)
{
    char detail[768];
    uint32_t turning = j->views - j->cfg->passes; /* the views whose angle is registered */
    int no_turn_seen = r->solved && r->turns_from_table > 0 && r->turns_from_table >= turning;
    if (r->few_samples > 0) {  /* before !solved: nothing was solved for it */
        char sparse[160] = ""; /* the samples thinned to fit this many views (reg_begin) */
        if (r->stride > j->cfg->registration.sample_stride)
            snprintf(sparse, sizeof(sparse),
                     " (thinned from one every %u to fit %u views: fewer views keep more)",
                     (unsigned)j->cfg->registration.sample_stride, (unsigned)j->views);
        snprintf(detail, sizeof(detail),
                 "turntable angles kept, the axis as calibrated: the views hold too few points "
                 "to register (the fullest %u samples, one every %u pixels across%s; %u "
                 "needed)%s",
                 (unsigned)r->few_samples, (unsigned)r->stride, sparse, REG_MIN_VIEW_SAMPLES,
                 j->said_dark ? "" /* the error below says why */
                              : ": the object is small in the camera's image. A camera nearer "
                                "the object, or a longer lens, scans it in more detail");
    } else if (!r->solved)
        snprintf(detail, sizeof(detail),
                 "turntable angles kept ([registration] icp = 0 or one "
                 "view)");
    else {
        char loop[48] = "loop closure cut at the move"; /* the last view and the first: apart */
        if (r->moved_view < 0 || r->loop_rms_mm > 0.0)  /* no pair closes a ring cut there */
            snprintf(loop, sizeof(loop), "loop closure %.3f mm", r->loop_rms_mm);
        snprintf(detail, sizeof(detail),
                 "residual %.3f mm, %s, worst view %u (%.3f mm); axis moved %.2f mm, tilted %.3f "
                 "deg; %.2f s CPU; %s",
                 r->rms_mm, loop, (unsigned)r->worst_view, r->worst_rms_mm, r->axis_shift_mm,
                 r->axis_tilt_deg, cpu_seconds,
                 r->accepted || no_turn_seen ? "" : "turntable angles kept: ");
    }
    size_t n = strlen(detail);
    const char *axis = r->axis_from_calibration || !r->accepted ? "as calibrated" : "registered";
    if (no_turn_seen && r->apart_pairs > 0) /* nothing to compare, not a shape that hides it */
        snprintf(detail + n, sizeof(detail) - n,
                 "views %d and %d share no surface to register (too few views for this "
                 "object?): the table's angles kept, the axis as calibrated",
                 r->apart_against, r->apart_view);
    else if (no_turn_seen && r->turns_little_shared > 0)
        snprintf(detail + n, sizeof(detail) - n,
                 "the views' turns are not fixed by the object (%u of %u share too little "
                 "surface with their neighbours: more views would): the table's angles kept, "
                 "the axis %s",
                 (unsigned)r->turns_little_shared, (unsigned)turning, axis);
    else if (no_turn_seen) /* the table's answer, whatever the solve did */
        snprintf(detail + n, sizeof(detail) - n,
                 "the object's shape does not fix the views' turns (a surface of revolution "
                 "about the axis?): the table's angles kept, the axis %s",
                 axis);
    else if (r->solved && r->accepted && r->turns_from_table == 0)
        snprintf(detail + n, sizeof(detail) - n, "the views' angles corrected");
    else if (r->solved && r->accepted) {
        char shared[80] = " ("; /* and how many of them share too little surface, if any */
        if (r->turns_little_shared > 0)
            snprintf(shared, sizeof(shared),
                     " or that share too little surface with their neighbours (%u; ",
                     (unsigned)r->turns_little_shared);
        char paint[96] = ""; /* and how many of them their paint turned */
        if (r->turns_by_paint > 0)
            snprintf(paint, sizeof(paint), "; %u turned from it to where the paint agrees",
                     (unsigned)r->turns_by_paint);
        snprintf(detail + n, sizeof(detail) - n,
                 "the views' angles corrected but for %u whose turn the object's shape does not "
                 "fix%sthe table's angle kept there%s)",
                 (unsigned)r->turns_from_table, shared, paint);
    } else if (r->solved)
        snprintf(detail + n, sizeof(detail) - n, "%s", r->refused);
    if (r->apart_pairs > 0 && !no_turn_seen) {
        n = strlen(detail);
        snprintf(detail + n, sizeof(detail) - n,
                 "; %u pair%s of neighbouring views share no surface (views %d and %d): the "
                 "table's angle holds between them",
                 (unsigned)r->apart_pairs, r->apart_pairs == 1 ? "" : "s", r->apart_against,
                 r->apart_view);
    }
    if (r->accepted && r->arcs_held > 0 && !no_turn_seen) {
        n = strlen(detail);
        snprintf(detail + n, sizeof(detail) - n,
                 "; pairs of neighbouring views that share only a top cut the views into %u "
                 "arcs whose turns against each other the object's shape does not fix: the "
                 "table's angles hold between them",
                 (unsigned)(r->arcs_held + 1));
    }
    if (r->views_alike && !no_turn_seen) {
        n = strlen(detail);
        snprintf(detail + n, sizeof(detail) - n,
                 "; each view%s looks like its neighbour as they stand (the object's symmetry "
                 "matches the table's step): the calibrated axis kept, which such views cannot "
                 "place (a number of views its symmetry does not divide lets them)",
                 r->moved_view >= 0 ? " before the object moved" : "");
    } else if (r->axis_unpaid && r->accepted && !no_turn_seen) {
        n = strlen(detail);
        snprintf(detail + n, sizeof(detail) - n,
                 "; the calibrated axis kept: moving it fitted the views no better than their "
                 "own errors explain (F %.2f)",
                 r->axis_f);
    } else if (r->axis_from_calibration && !r->axis_unpaid && !no_turn_seen) {
        n = strlen(detail);
        snprintf(detail + n, sizeof(detail) - n,
                 "; the views share too little to place the axis: the calibrated one kept");
    }
    if (r->moved_view >= 0) {
        n = strlen(detail);
        snprintf(
            detail + n, sizeof(detail) - n,
            "; the object moved on the table at view %d: %u view%s placed by the object's "
            "%s, as it had moved %.1f mm and turned %.1f deg",
            r->moved_view, (unsigned)r->moved_views, r->moved_views == 1 ? "" : "s",
            r->moved_by_colour == 2 ? "shape and colour (its shape alone lets them slide two ways)"
            : r->moved_by_colour == 1 ? "shape and colour (its shape alone lets them slide one way)"
                                      : "shape alone",
            r->moved_mm, r->moved_deg);
    }
    if (j->cfg->passes == 2 && r->failed_view < 0) {
        n = strlen(detail);
        snprintf(detail + n, sizeof(detail) - n,
                 "; second pass found turned %.1f deg, residual %.3f mm over %u pairs",
                 r->second_turned_deg, r->second_rms_mm, (unsigned)r->second_coupled);
    }
    char fields[224];
    snprintf(fields, sizeof(fields),
             "\"solved\":%d,\"accepted\":%d,\"residual_mm\":%.4f,\"loop_closure_mm\":%.4f,"
             "\"cpu_s\":%.3f,\"turns_from_table\":%u,\"turns_little_shared\":%u,"
             "\"moved_view\":%d",
             r->solved, r->accepted, r->rms_mm, r->loop_rms_mm, cpu_seconds,
             (unsigned)r->turns_from_table, (unsigned)r->turns_little_shared, r->moved_view);
    job_progress_with(j, EV_REGISTRATION, -1, j->views, fields, detail);
    if (r->few_samples > 0 && j->said_dark) { /* nearly empty views: not a model worth making */
        char why[64];
        snprintf(why, sizeof(why), "the fullest view holds %u samples", (unsigned)r->few_samples);
        say_too_dark(j, why, scan_dir);
        return -EPROTO;
    }
    if (r->failed_view >= 0 && r->failed_against < 0 && r->few_samples > 0) {
        j->hal->log(HAL_LOG_ERROR,
                    "registration failed: the second pass (from view %d) cannot be found in the "
                    "first: the views hold too few points (the object is small in the camera's "
                    "image, as said above). No model was made; the views are kept in %s. Scan "
                    "it in one pass, or with the camera nearer the object",
                    r->failed_view, scan_dir);
        return -EPROTO;
    }
    if (r->failed_view >= 0 && r->failed_against < 0) {
        j->hal->log(HAL_LOG_ERROR,
                    "registration failed: the second pass (from view %d) matches nothing of the "
                    "first (%.0f%% of its points paired, at least %.0f%% needed): was it the same "
                    "object? No model was made; the views are kept in %s",
                    r->failed_view, 100.0 * r->failed_share,
                    100.0 * j->cfg->registration.min_coupled_share, scan_dir);
        return -EPROTO;
    }
    if (!r->solved || r->failed_view < 0)
        return 0;
    if (r->moved_unfixed)
        j->hal->log(HAL_LOG_ERROR,
                    "registration failed: the object moved on the table at view %d, and the "
                    "views from it fit the others only up to a slide that neither the object's "
                    "shape (flat faces, parallel) nor its colour fixes: there is no telling how "
                    "far it moved. No model was made; the views are kept in %s. Scan again "
                    "without touching the object, or with paint or a marker on its faces",
                    r->failed_view, scan_dir);
    else if (r->failed_colour > 0.0)
        j->hal->log(HAL_LOG_ERROR,
                    "registration failed: view %d fits view %d in shape but not in colour (their "
                    "paint misses by %.0f%% of a full miss, the other pairs' far less): the "
                    "object slid along its faces on the table, and no placement of the views "
                    "from it fits the others. No model was made; the views are kept in %s. "
                    "Scan again without touching the object",
                    r->failed_view, r->failed_against, 100.0 * r->failed_colour, scan_dir);
    else if (j->said_dark) { /* the views are nearly empty: that, not the calibration */
        char why[96];
        snprintf(why, sizeof(why),
                 "view %d does not match view %d (%.0f%% of their overlap couples)", r->failed_view,
                 r->failed_against, 100.0 * r->failed_share);
        say_too_dark(j, why, scan_dir);
    } else
        j->hal->log(
            HAL_LOG_ERROR,
            "registration failed: view %d does not match view %d (%.0f%% of their overlap "
            "couples, at least %.0f%% needed), and no placement of it fits the other views "
            "either: was something else on the table, nothing in view, or is the calibration "
            "not this rig's (a nominal file: run 'scanner calibrate')? No model was made; "
            "the views are kept in %s. Scan again, or fuse them at the turntable's angles "
            "with 'scanner process %s --config F' where F has [registration] icp = 0",
            r->failed_view, r->failed_against, 100.0 * r->failed_share,
            100.0 * j->cfg->registration.min_coupled_share, scan_dir, scan_dir);
    return -EPROTO;
}

/* [colour] method = fit: view @p v's colour frames read back from @p scan_dir into the
 * firmware's buffers (range.bin keeps the view's colour, not its frames), and its colour made
 * again with them: while the pool collects, the multi estimate and samples; once the lobes are
 * fitted, the diffuse colour under them. */
static int recolour_from_frames(struct job *j, const char *scan_dir, uint32_t v,
                                struct scan_view *view)
{
    const struct scan_params *p = &j->cfg->scan;
    struct gray_layout layout;
    scan_layout(p, j->calib, &layout);
    uint32_t count = gray_layout_count(&layout), lights = scan_light_frame_count(p, j->calib);
    uint32_t white = p->exposure_count > 0 ? count + lights : GRAY_PATTERN_WHITE;
    char err[SCAN_DIR_PATH_MAX + 256];
    int rc = scan_begin_colour(j->scan, p, j->calib); /* the decoder not needed */
    if (rc != 0)
        snprintf(err, sizeof(err), "view %u: no room for them (%s)", (unsigned)v, strerror(-rc));
    for (uint32_t f = count; rc == 0 && f <= count + lights; f++) {
        uint32_t frame = f < count + lights ? f : white; /* the lights, then the white colour */
        if (f < count + lights && !scan_needs_light_frame(p, j->calib, f - count))
            continue; /* taken for another method */
        uint8_t *pixels;
        rc = job_read_into_buffer(j->scan, scan_dir, v, frame, 3, p, &pixels, err, sizeof(err));
        if (rc == 0 && f < count + lights)
            rc = scan_feed_light_frame(j->scan, f - count, pixels);
    }
    if (rc != 0) {
        j->hal->log(HAL_LOG_ERROR, "[colour] method = fit needs the colour frames: %s", err);
        return rc;
    }
    scan_attach_colour(j->scan, view);
    struct hal_thread cores = scan_cores(&j->hal->thread, p);
    return scan_recolour(&p->colour, &cores, j->calib, view, j->pool);
}

/* View @p v as the model is made of it (load_range), coloured again from its frames while the
 * reflectance pool collects (fit); stopped by request between views. Once the reflectance is
 * fitted, each view's range.bin holds the colour under it (recolour_views). */
int job_view_for_model(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                       struct scan_view_info *info)
{
    int rc = job_stopped_offline(j, scan_dir, v);
    if (rc == 0)
        rc = job_load_range(j, scan_dir, v, view, info);
    if (rc == 0 && reflect_collecting(j->pool))
        rc = recolour_from_frames(j, scan_dir, v, view);
    return rc;
}

/* [colour] method = fit, the reflectance fitted: each view coloured again from its frames under
 * it and kept so in its range.bin in the output directory, which the fusion and the texture read
 * (the colour frames' memory is the volume's from the fusion on: job.c). */
static int recolour_views(struct job *j, const char *scan_dir)
{
    int rc = 0;
    for (uint32_t v = 0; v < j->views && rc == 0; v++) {
        struct scan_view view;
        struct scan_view_info info;
        rc = job_stopped_offline(j, scan_dir, v);
        if (rc == 0)
            rc = job_load_range(j, scan_dir, v, &view, &info);
        if (rc == 0)
            rc = recolour_from_frames(j, scan_dir, v, &view);
        if (rc == 0)
            rc = job_write_failed(j, v, SCAN_FILE_RANGE,
                                  scan_dir_write_range(&j->hal->storage, j->out_dir, v, &view));
    }
    return rc;
}

/* [colour] method = fit: the samples of every view (each view's colour frames read back), the
 * clusters and their lobes fitted, said and kept in reflectance.ini. Too few samples: the views
 * keep the multi estimate, said. */
static int fit_reflectance(struct job *j, const char *scan_dir)
{
    reflect_forget(j->pool);
    if (j->cfg->scan.colour.method != COLOUR_FIT)
        return 0;
    double t0 = clock_posix_thread_cpu_s();
    reflect_begin(j->pool, j->views);
    int rc = 0;
    for (uint32_t v = 0; v < j->views && rc == 0; v++) {
        struct scan_view view;
        struct scan_view_info info;
        rc = job_view_for_model(j, scan_dir, v, &view, &info);
    }
    struct reflect_model m;
    if (rc == 0 && (rc = reflect_fit(j->pool, j->cfg->scan.colour.clusters, &m)) == -ENODATA) {
        j->hal->log(HAL_LOG_WARN, "reflectance: too few samples to fit (lit, unsaturated "
                                  "surface seen by two lights or more); the views keep the "
                                  "multi method's colour");
        return 0;
    }
    if (rc == 0)
        rc = job_write_failed_at(j, j->out_dir, SCAN_FILE_REFLECTANCE,
                                 scan_dir_write_reflectance(&j->hal->storage, j->out_dir, &m));
    if (rc == 0)
        rc = recolour_views(j, scan_dir);
    if (rc != 0)
        return rc;
    char detail[128 + REFLECT_MAX_CLUSTERS * 112];
    size_t len = (size_t)snprintf(detail, sizeof(detail),
                                  "%u material clusters (%.2f s CPU):", (unsigned)m.count,
                                  clock_posix_thread_cpu_s() - t0);
    for (uint32_t k = 0; k < m.count && len < sizeof(detail); k++) {
        const struct reflect_cluster *c = &m.cluster[k];
        len += (size_t)snprintf(detail + len, sizeof(detail) - len,
                                "%s diffuse %.2f %.2f %.2f, specular %.3f %.3f %.3f, roughness "
                                "%.3f, retro %.3f (%u samples)",
                                k ? ";" : "", c->centre[0], c->centre[1], c->centre[2],
                                c->specular[0], c->specular[1], c->specular[2], c->roughness,
                                c->retro, (unsigned)c->samples);
    }
    char fields[64];
    snprintf(fields, sizeof(fields), "\"clusters\":%u", (unsigned)m.count);
    job_progress_with(j, EV_REFLECTANCE, -1, j->views, fields, detail);
    return 0;
}

/* What the registered views saw, against the configured volume (fit_volume). */
struct seen {
    struct fusion_outside o;
    const struct fusion_params *p;
};

static void count_seen(void *priv, vec3 p_obj)
{
    struct seen *seen = priv;
    fusion_outside_add(&seen->o, seen->p, p_obj);
}

/* [fusion] fit_volume: the volume grown to hold what the registered views saw (their samples),
 * so that a taller or wider object than radius_mm and top_mm is not cut; said when it grows.
 * @param fp  out: the volume to fuse in */
static void fit_volume(struct job *j, struct fusion_params *fp)
{
    const struct fusion_params *cfg = &j->cfg->fusion;
    struct seen seen = {.p = cfg};
    reg_each_point(j->reg, count_seen, &seen);
    if (fusion_fit(cfg, &seen.o, fp) != 1)
        return;
    char top[96] = "", radius[192] = "", centre[96] = "";
    if (fp->top_mm != cfg->top_mm)
        snprintf(top, sizeof(top), "top_mm %g -> %.1f (it reaches %.0f mm up)", cfg->top_mm,
                 fp->top_mm, seen.o.top_seen_mm);
    if (fp->centre_mm[0] != cfg->centre_mm[0] || fp->centre_mm[1] != cfg->centre_mm[1])
        snprintf(centre, sizeof(centre),
                 ", about x = %.0f, y = %.0f mm (the object stands off the axis)", fp->centre_mm[0],
                 fp->centre_mm[1]);
    if (fp->radius_mm != cfg->radius_mm)
        snprintf(radius, sizeof(radius), "radius_mm %g -> %g (%.0f mm out)%s", cfg->radius_mm,
                 fp->radius_mm, seen.o.reach_seen_mm, centre);
    j->hal->log(HAL_LOG_INFO,
                "the fused volume grown to hold the object ([fusion] fit_volume): %s%s%s", top,
                top[0] != '\0' && radius[0] != '\0' ? ", " : "", radius);
}

/* The smallest multiple of 5 mm at least @p mm + 5 (a suggested bound with room). */
static double bound_with_room(double mm)
{
    return 5.0 * ceil((mm + 5.0) / 5.0);
}

/* An object taller or wider than [fusion]'s volume is cut at its walls: said, with the key to
 * change and the value that holds what the views saw, or that this build cannot (the grid's
 * compiled limits), so that a cut model is never taken for the object; and one that runs off
 * the camera's image, which no setting of the volume brings back. Points are counted where
 * they are many enough not to be stray ones (at least 100, and a thousandth of those fused). */
static void report_outside(struct job *j, const struct fusion_params *fp)
{
    struct fusion_outside o;
    fusion_outside(j->vol, &o);
    if (o.views_cut > 0)
        job_warn(j,
                 "the object runs off the camera's image in %u of %u views: what lies beyond "
                 "the image's edge is not scanned (the camera farther away, or the object "
                 "laid down for a second pass, [scan] passes = 2)",
                 (unsigned)o.views_cut, (unsigned)j->views);
    for (int side = 0; side < 2; side++) {
        uint64_t n = side ? o.beside : o.above;
        if (!fusion_outside_many(n, o.fused, 100))
            continue;
        struct fusion_params want = *fp;
        double seen = side ? o.reach_seen_mm : o.top_seen_mm;
        if (side)
            want.radius_mm = bound_with_room(seen);
        else
            want.top_mm = bound_with_room(seen);
        uint32_t dims[3];
        char fix[160];
        if (fusion_dims(&want, dims) == 0)
            snprintf(fix, sizeof(fix), "set %s = %.0f", side ? "radius_mm" : "top_mm",
                     side ? want.radius_mm : want.top_mm);
        else
            snprintf(fix, sizeof(fix),
                     "%s = %.0f is more than this build fuses at voxel_mm = %g (%u voxels a side, "
                     "%u in all): a larger voxel_mm",
                     side ? "radius_mm" : "top_mm", side ? want.radius_mm : want.top_mm,
                     fp->voxel_mm, FUSION_MAX_DIM, FUSION_MAX_VOXELS);
        int off_axis = fp->centre_mm[0] != 0.0 || fp->centre_mm[1] != 0.0;
        job_warn(j,
                 "the object %s the fused volume: %.1f%% of the views' points lie %s [fusion] "
                 "%s = %g, up to %.0f mm, and are not in the model: %s in [fusion]",
                 side ? "reaches beyond the sides of" : "rises above",
                 100.0 * (double)n / (double)o.fused,
                 !side      ? "higher than"
                 : off_axis ? "farther from the volume's centre (moved off the axis) than"
                            : "farther from the axis than",
                 side ? "radius_mm" : "top_mm", side ? fp->radius_mm : fp->top_mm, seen, fix);
    }
}

/* Once every view is in: register them jointly, then fuse each at its registered pose. The
 * fusion must wait for the registration, and the views' range images are not kept in memory
 * (a view's are 40 MB): each is read back from its range.bin in the output directory, or, for a
 * scan kept before range.bin existed, decoded again from its frames in @p scan_dir. */
int job_make_model(struct job *j, const char *scan_dir)
{
    struct reg_report rep;
    scan_release_frames(j->scan); /* the views are taken: their frames' memory serves the grid */
    double t0 = clock_posix_thread_cpu_s();
    reg_solve(j->reg, &rep);
    int rc = report_registration(j, &rep, clock_posix_thread_cpu_s() - t0, scan_dir);
    if (rc == 0)
        rc = fit_reflectance(j, scan_dir);
    struct fusion_params fp = j->cfg->fusion;
    if (rc == 0) {
        fit_volume(j, &fp);
        job_lend_frames(j);
        rc = fusion_begin(j->vol, &fp);
    }
    for (uint32_t v = 0; v < j->views && rc == 0; v++) {
        struct scan_view view;
        struct scan_view_info info;
        rc = job_view_for_model(j, scan_dir, v, &view, &info);
        if (rc == 0)
            rc = job_make_view_dir(j, v);
        struct reg_view rv;
        if (rc == 0)
            rc = save_results(j, v, &view, &rep, &rv);
        if (rc == 0) {
            char detail[HAL_MAX_PATH + 160], dir[SCAN_DIR_PATH_MAX];
            char fields[96];
            job_view_dir(j, v, dir, sizeof(dir));
            snprintf(detail, sizeof(detail), "fused at %.3f deg (%+.3f deg from the table's) -> %s",
                     rv.angle_deg, rv.correction_deg, dir);
            snprintf(fields, sizeof(fields), "\"angle_deg\":%.4f,\"correction_deg\":%.4f",
                     rv.angle_deg, rv.correction_deg);
            job_progress_with(j, EV_FUSED, (int)v, v + 1, fields, detail);
        }
    }
    if (rc == 0)
        report_outside(j, &fp);
    return rc == 0 ? write_model(j, scan_dir) : rc;
}

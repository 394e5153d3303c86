/* One simulated view against ground truth: decoding rate, depth error, and no outliers
 * (issue "scanner core", done-when). Sphere and Stanford bunny, default noise. */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gray.h"
#include "mem.h"
#include "memory_posix.h"
#include "job.h"
#include "scan_job.h"
#include "storage_posix.h"
#include "test_util.h"
#include "thread_posix.h"

/* The fusion volume of the tests that fuse (one: it is most of a gigabyte at the limits). */
static struct fusion_volume test_volume;

/* One view of the rig @p t (loaded, its settings as the test wants them), measured. */
static void take_and_measure(struct test_rig *t, struct view_quality *q,
                             struct scan_view_info *info)
{
    assert_int_equal(test_rig_start(t), 0);
    struct scan_view view;
    assert_int_equal(
        scan_take_view(t->scan, &t->hal, &t->cfg.scan, &t->calib, 0, NULL, &view, info), 0);
    test_measure_view(sim_ctl_rig(), &view, q);
    test_rig_stop(t);
}

static void scan_and_measure_with(const char *config, const char *object, struct view_quality *q)
{
    static struct test_rig t;
    struct scan_view_info info;
    assert_int_equal(test_rig_load(&t, config), 0);
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "%s", object);
    take_and_measure(&t, q, &info);
    assert_int_equal(info.valid_points, q->valid);
    print_message("%s: %u lit, %.2f%% right (+-1), %.2f%% head-on right, depth RMS %.3f mm "
                  "(%.3f%% of %.0f mm), max %.2f mm from the surface, %u of %u dark flagged, "
                  "normals %.1f deg\n",
                  object, q->lit, 100.0 * q->lit_correct / q->lit,
                  100.0 * q->lit_head_on_correct / q->lit_head_on, q->depth_rms_mm,
                  100.0 * q->depth_rms_mm / q->distance_mm, q->distance_mm, q->max_surface_mm,
                  q->dark_flagged, q->dark, q->normal_err_deg);
}

static void scan_and_measure(const char *object, struct view_quality *q)
{
    scan_and_measure_with("config/sim.ini", object, q);
}

static void check_quality(const struct view_quality *q)
{
    /* >= 98% of the lit surface decodes to the right column (+-1), where the projector lights
     * it at less than 75 degrees incidence and the paint is not the very dark one. */
    assert_true(q->lit_head_on > 50000);
    assert_true(q->lit_head_on_correct >= 0.98 * q->lit_head_on);
    /* Grazing light included, still most of it. */
    assert_true(q->lit_correct >= 0.88 * q->lit);
    /* Depth RMS below 0.2% of the camera-to-object distance. */
    assert_true(q->depth_rms_mm < 0.002 * q->distance_mm);
    /* Shadowed and very dark pixels are flagged, never triangulated into outliers. */
    assert_int_equal(q->valid_unlit, 0);
    assert_int_equal(q->outliers_2mm, 0);
    assert_true(q->max_surface_mm < 2.0);
    assert_true(q->dark > 500);
    assert_true(q->dark_flagged >= 0.99 * q->dark);
}

static void test_sphere(void **state)
{
    (void)state;
    struct view_quality q;
    scan_and_measure("sphere", &q);
    check_quality(&q);
}

static void test_bunny(void **state)
{
    (void)state;
    struct view_quality q;
    scan_and_measure("mesh", &q);
    check_quality(&q);
}

/* At the camera's limit (config/sim-limit.ini: the finest stripe under 2 camera pixels, a
 * defocused projector, a soft lens, JPEG frames): the per-pixel thresholds and the
 * neighbourhood's resolution of unclear bits keep the lit surface, and what they keep is right.
 * Measured by make measure (second table): 98.65% valid, 0.11% more than a column off, all of
 * those at the silhouette where a blurred pixel sees the background's neighbour; 94.7% valid
 * without the resolution. */
static void test_sphere_at_the_cameras_limit(void **state)
{
    (void)state;
    struct view_quality q;
    scan_and_measure_with("config/sim-limit.ini", "sphere", &q);
    print_message("finest stripe %.2f px: %.2f%% valid, %.3f%% off, %u wrong\n", q.stripe_px,
                  100.0 * q.lit_head_on_valid / q.lit_head_on,
                  100.0 * q.lit_head_on_off / q.lit_head_on, q.lit_head_on_wrong);
    assert_true(q.stripe_px <= 2.0);
    assert_true(q.lit_head_on_valid >= 0.98 * q.lit_head_on);
    assert_true(q.lit_head_on_off <= 0.003 * q.lit_head_on);
    assert_true(q.lit_head_on_wrong <= 0.0002 * q.lit_head_on);
    /* A blurred pixel just off the silhouette sees the sphere's edge: a few such points float
     * beside it (19 here, 30 with the old decoder); not yet filtered. */
    assert_true(q.valid_unlit <= 0.0005 * q.valid);
}

/* HDR patterns ([scan] exposures_us): the very dark paint (albedo 0.03: 2-5 grey levels of
 * contrast at the camera's exposure, every pixel flagged) decodes at the longer exposure, and the
 * rest of the sphere keeps the camera's. A glossy sphere's highlights, saturated in the white
 * frame, decode without HDR: saturation is judged per pattern pair. */
static void test_dark_paint_with_hdr_and_highlights(void **state)
{
    (void)state;
    static struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim-glossy.ini"), 0);
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "sphere");
    t.cfg.scan.exposure_count = 2;
    t.cfg.scan.exposures_us[0] = 10000;
    t.cfg.scan.exposures_us[1] = 40000;
    struct scan_view_info info;
    struct view_quality q;
    take_and_measure(&t, &q, &info);
    assert_int_equal(info.frames_captured, 44);
    print_message("HDR: %u of %u dark paint pixels right\n", q.dark_correct, q.dark);
    assert_true(q.dark > 1000);
    assert_true(q.dark_correct >= 0.9 * q.dark);
    assert_true(q.lit_head_on_correct >= 0.98 * q.lit_head_on); /* the rest as without HDR */
    assert_int_equal(q.outliers_2mm, 0);

    assert_int_equal(test_rig_load(&t, "config/sim-glossy.ini"), 0);
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "sphere");
    snprintf(t.cfg.sim.material, sizeof(t.cfg.sim.material), "phong");
    take_and_measure(&t, &q, &info);
    print_message("glossy: %u of %u saturated pixels right\n", q.saturated_correct, q.saturated);
    assert_true(q.saturated > 1000);
    assert_true(q.saturated_correct >= 0.8 * q.saturated);
}

static void groove_view(uint32_t code, struct view_quality *q)
{
    static struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim-concave.ini"), 0);
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "groove");
    t.cfg.scan.code = code;
    struct scan_view_info info;
    take_and_measure(&t, q, &info);
    print_message("groove, %s: %.2f%% valid, %.3f%% wrong\n", code ? "XOR-04" : "Gray",
                  100.0 * q->lit_valid / q->lit, 100.0 * q->lit_wrong / q->lit);
}

/* Interreflections (config/sim-concave.ini: a white 60-degree groove, the projector's light
 * bounced once between its walls): plain Gray code reads coarse bits wrong where the other wall's
 * bounced light outshines the direct light; XOR-04, every pattern in fine stripes, does not. */
static void test_interreflection_gray_against_xor04(void **state)
{
    (void)state;
    struct view_quality gray, xor04;
    groove_view(GRAY_CODE_GRAY, &gray);
    groove_view(GRAY_CODE_XOR04, &xor04);
    assert_true(gray.lit_wrong > 0.05 * gray.lit); /* the scene does defeat Gray */
    assert_true(xor04.lit_wrong <= 0.01 * xor04.lit);
    assert_true(xor04.lit_valid >= 0.95 * xor04.lit);
}

/* The blocked decoder equals the plain per-pixel reference on real simulated frames, columns
 * and rows (@p patterns of them: inverses for the finest @p inverse_bits bits, 0 every bit),
 * pixel for pixel: column, row and reason. */
static void blocked_matches_reference(uint32_t inverse_bits, uint32_t patterns)
{
    static struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    t.cfg.scan.decode_rows = 1;
    t.cfg.scan.inverse_bits = inverse_bits;
    assert_int_equal(test_rig_start(&t), 0);
    struct scan_view_info info;
    struct test_frames kept = {.pixels = (size_t)t.cfg.scan.width * t.cfg.scan.height,
                               .saturation_dn = t.cfg.scan.saturation_dn};
    struct scan_frame_sink sink = test_frames_sink(&kept);
    /* captured, not finished (its range image would take the decoder's working planes) */
    assert_int_equal(scan_capture_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, &sink, &info), 0);
    /* rows and columns, then the colour frames of config/sim.ini's method */
    assert_int_equal(info.frames_captured,
                     patterns + scan_light_frame_count(&t.cfg.scan, &t.calib));
    struct gray_layout layout;
    scan_layout(&t.cfg.scan, &t.calib, &layout);
    const uint8_t *frames[DECODE_MAX_PATTERNS];
    for (uint32_t p = 0; p < gray_layout_count(&layout); p++) {
        assert_non_null(kept.grey[p]);
        frames[p] = kept.grey[p];
    }
    static uint8_t pixel_reason[HAL_MAX_PIXELS];
    struct decode_maps pixel_maps;
    /* again, without the neighbour check */
    assert_int_equal(decode_pixels(&t.scan->decode, NULL, pixel_reason, &pixel_maps), 0);
    const struct decode_maps *m = &pixel_maps;
    size_t n = (size_t)m->width * m->height;
    static uint16_t col[HAL_MAX_PIXELS], row[HAL_MAX_PIXELS];
    static uint8_t reason[HAL_MAX_PIXELS];
    decode_reference(&t.cfg.scan, &layout, t.calib.proj_width, t.calib.proj_height, frames, n, col,
                     row, reason);
    size_t valid = 0, row_right = 0;
    const struct sim_rig *rig = sim_ctl_rig();
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(m->reason[i], reason[i]);
        if (reason[i] != SCAN_VALID)
            continue;
        assert_int_equal(m->column[i], col[i]);
        assert_int_equal(m->row[i], row[i]);
        valid++;
        row_right += fabs((double)row[i] - floor(rig->truth.proj_v[i] + 0.5)) <= 1.0;
    }
    test_rig_stop(&t);
    test_frames_free(&kept);
    print_message("%zu valid pixels identical; rows right (+-1) at %.2f%%\n", valid,
                  100.0 * row_right / valid);
    assert_true(valid > 100000);
    assert_true(row_right > 0.98 * valid);
}

static void test_blocked_decoder_matches_reference(void **state)
{
    (void)state;
    blocked_matches_reference(0, 42);
}

/* The decode split across threads (hal_thread, POSIX threads; 1 to 8, more than this machine's
 * cores too) gives the maps of one thread to the byte: columns, rows, reasons; the view's colour,
 * its range image (refined columns, points, normals) and its fusion likewise, pixel for pixel
 * and voxel for voxel. */
static void test_threads_decode_the_same(void **state)
{
    (void)state;
    static struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "mesh");
    t.cfg.scan.decode_rows = 1;
    assert_int_equal(test_rig_start(&t), 0);
    struct scan_view view;
    struct scan_view_info info;
    /* captured, not finished: decode_finish again and again on the same frames' bits */
    assert_int_equal(scan_capture_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &info), 0);
    static uint8_t reason1[HAL_MAX_PIXELS], reason[HAL_MAX_PIXELS];
    static uint16_t col1[HAL_MAX_PIXELS], row1[HAL_MAX_PIXELS];
    struct decode_maps m;
    assert_int_equal(decode_finish(&t.scan->decode, NULL, reason1, &m), 0);
    size_t n = (size_t)m.width * m.height, valid = 0;
    memcpy(col1, m.column, n * sizeof(uint16_t));
    memcpy(row1, m.row, n * sizeof(uint16_t));
    for (size_t i = 0; i < n; i++)
        valid += reason1[i] == SCAN_VALID;
    for (unsigned threads = 2; threads <= HAL_MAX_THREADS; threads *= 2) {
        struct hal_thread cores;
        thread_posix_init(&cores, threads);
        assert_int_equal(cores.threads, threads);
        assert_int_equal(decode_finish(&t.scan->decode, &cores, reason, &m), 0);
        assert_memory_equal(reason, reason1, n);
        assert_memory_equal(m.column, col1, n * sizeof(uint16_t));
        assert_memory_equal(m.row, row1, n * sizeof(uint16_t));
    }
    /* the view finished on one thread (once a view: its range image takes the decoder's
     * working planes), and its colour (config/sim.ini's method, multi, both passes): the same
     * on 1 and 4 threads */
    struct hal_thread four;
    thread_posix_init(&four, 4);
    assert_int_equal(scan_finish_view(t.scan, NULL, &t.calib, 0, &view, &info), 0);
    assert_int_equal(scan_recolour(&t.cfg.scan.colour, NULL, &t.calib, &view, NULL), 0);
    static uint8_t rgb1[3 * HAL_MAX_PIXELS];
    static float conf1[HAL_MAX_PIXELS];
    memcpy(rgb1, view.rgb, 3 * n);
    memcpy(conf1, view.confidence, n * sizeof(float));
    assert_int_equal(scan_recolour(&t.cfg.scan.colour, &four, &t.calib, &view, NULL), 0);
    assert_memory_equal(view.rgb, rgb1, 3 * n);
    assert_memory_equal(view.confidence, conf1, n * sizeof(float));
    assert_int_equal(t.cfg.scan.colour.method, COLOUR_MULTI);
    /* and the view fused: every voxel the same on 1 and 4 threads */
    struct fusion_volume *vol = &test_volume;
    struct frame_xform pose;
    frame_object_from_camera(&t.calib, view.angle_mdeg, &pose);
    /* the whole view on 4 threads, its frames taken again (the simulator renders them the same
     * from a fresh start): points (made from the refined columns, whose memory the colour
     * takes after them), normals and reasons the same */
    static float xyz1[3 * HAL_MAX_PIXELS], normal1[3 * HAL_MAX_PIXELS];
    memcpy(reason1, view.maps.reason, n);
    memcpy(xyz1, view.range.xyz_mm, 3 * n * sizeof(float));
    memcpy(normal1, view.range.normal, 3 * n * sizeof(float));
    uint32_t points1 = view.range.valid_count;
    test_rig_stop(&t);
    assert_int_equal(test_rig_start(&t), 0);
    assert_int_equal(scan_capture_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &info), 0);
    assert_int_equal(scan_finish_view(t.scan, &four, &t.calib, view.angle_mdeg, &view, &info), 0);
    assert_memory_equal(view.maps.reason, reason1, n);
    assert_memory_equal(view.range.xyz_mm, xyz1, 3 * n * sizeof(float));
    assert_memory_equal(view.range.normal, normal1, 3 * n * sizeof(float));
    assert_int_equal(view.range.valid_count, points1);
    assert_int_equal(info.valid_points, points1);
    assert_true(points1 > 100000);
    assert_int_equal(fusion_begin(vol, &t.cfg.fusion), 0);
    assert_int_equal(scan_fuse_view(vol, NULL, &t.calib, &view, &pose), 0);
    size_t voxels = (size_t)vol->dims[0] * vol->dims[1] * vol->dims[2], observed = 0;
    struct voxel *one = malloc(voxels * sizeof(*one));
    assert_non_null(one);
    memcpy(one, vol->grid, voxels * sizeof(*one));
    for (size_t i = 0; i < voxels; i++)
        observed += one[i].weight > 0;
    assert_int_equal(fusion_begin(vol, &t.cfg.fusion), 0);
    assert_int_equal(scan_fuse_view(vol, &four, &t.calib, &view, &pose), 0);
    assert_memory_equal(vol->grid, one, voxels * sizeof(*one));
    free(one);
    test_rig_stop(&t);
    print_message("%zu valid pixels, the same maps on 1, 2, 4 and 8 threads; %zu voxels observed, "
                  "the same on 1 and 4\n",
                  valid, observed);
    assert_true(valid > 100000);
    assert_true(observed > 100000);
}

/* One view of @p object (@p height_mm tall; 0: config/sim.ini's) taken and finished on the
 * started rig @p t, without colour, and its pose. */
static void take_one_view(struct test_rig *t, const char *object, double height_mm,
                          struct scan_view *view, struct frame_xform *pose)
{
    assert_int_equal(test_rig_load(t, "config/sim.ini"), 0);
    snprintf(t->cfg.sim.object, sizeof(t->cfg.sim.object), "%s", object);
    if (height_mm > 0.0)
        t->cfg.sim.object_height_mm = height_mm;
    t->cfg.scan.colour.method = COLOUR_NONE;
    assert_int_equal(test_rig_start(t), 0);
    struct scan_view_info info;
    assert_int_equal(
        scan_take_view(t->scan, &t->hal, &t->cfg.scan, &t->calib, 0, NULL, view, &info), 0);
    assert_int_equal(scan_finish_view(t->scan, NULL, &t->calib, view->angle_mdeg, view, &info), 0);
    frame_object_from_camera(&t->calib, view->angle_mdeg, pose);
}

/* One view of @p object, @p height_mm tall, fused with @p top_mm and @p radius_mm: what the
 * fusion counted beyond its volume and the image (struct fusion_outside). */
static void fuse_one_view(const char *object, double height_mm, double top_mm, double radius_mm,
                          struct fusion_outside *o)
{
    static struct test_rig t;
    struct fusion_volume *vol = &test_volume;
    struct scan_view view;
    struct frame_xform pose;
    take_one_view(&t, object, height_mm, &view, &pose);
    struct fusion_params p = t.cfg.fusion;
    p.top_mm = top_mm;
    p.radius_mm = radius_mm;
    assert_int_equal(fusion_begin(vol, &p), 0);
    assert_int_equal(scan_fuse_view(vol, NULL, &t.calib, &view, &pose), 0);
    fusion_outside(vol, o);
    test_rig_stop(&t);
    print_message("%s %.0f mm, top_mm %.0f, radius_mm %.0f: %llu points fused, %llu above (up to "
                  "%.1f mm), %llu beside (out to %.1f mm), %u views off the image\n",
                  object, height_mm, top_mm, radius_mm, (unsigned long long)o->fused,
                  (unsigned long long)o->above, o->top_seen_mm, (unsigned long long)o->beside,
                  o->reach_seen_mm, (unsigned)o->views_cut);
}

/* An object taller than the volume and the image (a cylinder 290 mm tall, 87 mm in radius; the
 * camera sees up to about 200 mm of it) is counted above the volume's top and off the image; with
 * a narrower volume, beside it; the bunny, 150 mm, inside both (job_model.c says it). */
static void test_object_beyond_the_volume_counted(void **state)
{
    (void)state;
    struct fusion_outside o;
    fuse_one_view("cylinder", 290.0, 165.0, 100.0, &o);
    assert_int_equal(o.views_cut, 1);
    assert_true(o.above > 20000 && o.above * 10 > o.fused);
    assert_true(o.top_seen_mm > 180.0 && o.top_seen_mm < 290.0);
    assert_int_equal(o.beside, 0);
    fuse_one_view("cylinder", 290.0, 300.0, 60.0, &o);
    assert_int_equal(o.above, 0);
    assert_true(o.beside > 20000);
    assert_true(o.reach_seen_mm > 80.0 && o.reach_seen_mm < 88.0);
    assert_int_equal(o.views_cut, 1);
    fuse_one_view("mesh", 150.0, 165.0, 100.0, &o);
    assert_true(o.fused > 100000);
    assert_int_equal(o.above + o.beside + o.views_cut, 0);
}

/* A volume moved off the axis by whole blocks of voxels (fusion_fit's centre_mm, for an object
 * near the table's rim) fuses a view into the same voxels at the same places: the bunny's view
 * in the volume about the axis and in one centred 20 mm away and 20 mm wider, every voxel the
 * two share the same to the byte, and every voxel the view reached inside both. */
static void test_volume_off_the_axis_fuses_the_same(void **state)
{
    (void)state;
    static struct test_rig t;
    struct fusion_volume *vol = &test_volume;
    struct scan_view view;
    struct frame_xform pose;
    take_one_view(&t, "mesh", 0.0, &view, &pose);
    struct fusion_params p = t.cfg.fusion, moved;
    assert_true(p.voxel_mm == 1.0 && p.centre_mm[0] == 0.0 && p.centre_mm[1] == 0.0);
    assert_int_equal(fusion_begin(vol, &p), 0);
    assert_int_equal(scan_fuse_view(vol, NULL, &t.calib, &view, &pose), 0);
    const uint32_t a[3] = {vol->dims[0], vol->dims[1], vol->dims[2]};
    const vec3 origin_a = vol->origin;
    size_t na = (size_t)a[0] * a[1] * a[2];
    struct voxel *one = malloc(na * sizeof(*one));
    assert_non_null(one);
    memcpy(one, vol->grid, na * sizeof(*one));
    moved = p;
    moved.centre_mm[1] = 20.0; /* 20 voxels: whole blocks of 4, as the fusion marks them */
    moved.radius_mm = p.radius_mm + 20.0;
    assert_int_equal(fusion_begin(vol, &moved), 0);
    assert_int_equal(scan_fuse_view(vol, NULL, &t.calib, &view, &pose), 0);
    test_rig_stop(&t);
    const long dx = lround(origin_a.x - vol->origin.x), dy = lround(origin_a.y - vol->origin.y);
    assert_true(dx == 20 && dy == 0 && vol->origin.z == origin_a.z);
    size_t same = 0, reached = 0;
    for (uint32_t z = 0; z < a[2]; z++)
        for (uint32_t y = 0; y < a[1]; y++)
            for (uint32_t x = 0; x < a[0]; x++) {
                const struct voxel *va = &one[((size_t)z * a[1] + y) * a[0] + x];
                long bx = (long)x + dx, by = (long)y + dy;
                if (bx >= (long)vol->dims[0] || by >= (long)vol->dims[1]) {
                    assert_int_equal(va->weight, 0); /* only the axis' volume reaches there */
                    continue;
                }
                const struct voxel *vb =
                    &vol->grid[((size_t)z * vol->dims[1] + (size_t)by) * vol->dims[0] + (size_t)bx];
                assert_memory_equal(va, vb, sizeof(*va));
                same++;
                reached += va->weight > 0;
            }
    print_message("%zu voxels in both, %zu of them reached by the view\n", same, reached);
    assert_true(reached > 100000);
    free(one);
}

/* Inverses for the finest 3 bits only ([scan] inverse_bits = 3: 28 patterns with rows, 15
 * without): the decoders still agree, and the bunny's view keeps its quality (check_quality), its
 * lit surface decoded right within 0.2 points of every inverse's, nothing more than 2 mm off
 * (make measure-inverse has the whole table). */
static void test_fewer_inverses(void **state)
{
    (void)state;
    blocked_matches_reference(3, 28);
    struct view_quality all, fewer;
    static struct test_rig t;
    struct scan_view_info info;
    for (uint32_t inverse_bits = 0; inverse_bits <= 3; inverse_bits += 3) {
        assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
        snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "mesh");
        t.cfg.scan.inverse_bits = inverse_bits;
        take_and_measure(&t, inverse_bits ? &fewer : &all, &info);
    }
    assert_int_equal(info.frames_captured, 15 + scan_light_frame_count(&t.cfg.scan, &t.calib));
    print_message("bunny: %.2f%% right with every inverse, %.2f%% with the finest 3\n",
                  100.0 * all.lit_correct / all.lit, 100.0 * fewer.lit_correct / fewer.lit);
    check_quality(&fewer);
    assert_true(fewer.lit == all.lit);
    assert_true(fabs((double)fewer.lit_correct - all.lit_correct) <= 0.002 * all.lit);
}

/* Two views in two scan contexts (struct scan_ctx): the second, taken at another angle into
 * its own context, leaves the first's reasons, points and colour exactly as they were, and the
 * two share no buffer. */
static void test_two_scan_contexts_are_independent(void **state)
{
    (void)state;
    static struct test_rig t;
    static struct scan_ctx other;
    static struct scan_light_frames other_light; /* its colour frames, its own too */
    static uint8_t reason_a[HAL_MAX_PIXELS], rgb_a[HAL_MAX_PIXELS * 3];
    static float xyz_a[HAL_MAX_PIXELS * 3];
    scan_use_light_frames(&other, &other_light);
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    assert_int_equal(test_rig_start(&t), 0);
    struct scan_view a, b;
    struct scan_view_info info_a, info_b;
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &a, &info_a),
                     0);
    size_t n = (size_t)a.width * a.height;
    memcpy(reason_a, a.maps.reason, n);
    memcpy(rgb_a, a.rgb, n * 3);
    memcpy(xyz_a, a.range.xyz_mm, n * 3 * sizeof(float));
    assert_int_equal(hal_table_move_to(&t.hal.turntable, 90000), 0);
    assert_int_equal(
        scan_take_view(&other, &t.hal, &t.cfg.scan, &t.calib, 90000, NULL, &b, &info_b), 0);
    test_rig_stop(&t);
    assert_true(info_a.valid_points > 10000 && info_b.valid_points > 10000);
    assert_ptr_not_equal(a.range.xyz_mm, b.range.xyz_mm);
    assert_ptr_not_equal(a.maps.reason, b.maps.reason);
    assert_ptr_not_equal(a.rgb, b.rgb);
    assert_true(memcmp(reason_a, b.maps.reason, n) != 0); /* another view indeed */
    assert_memory_equal(reason_a, a.maps.reason, n);
    assert_memory_equal(rgb_a, a.rgb, n * 3);
    for (size_t i = 0; i < n; i++)
        if (reason_a[i] == SCAN_VALID)
            assert_memory_equal(&xyz_a[3 * i], &a.range.xyz_mm[3 * i], 3 * sizeof(float));
    assert_int_equal(a.range.valid_count, info_a.valid_points);
}

/* The whole pages within @p n bytes at @p p all zero (a page a buffer shares with the data
 * before it is not given back). */
static int all_zero(const void *p, size_t n)
{
    size_t page = (size_t)sysconf(_SC_PAGESIZE), skip = (page - (uintptr_t)p % page) % page;
    const uint8_t *b = p;
    for (size_t i = skip; i < n; i++)
        if (b[i] != 0)
            return 0;
    return 1;
}

/* The views' frames given back (scan_release_frames, as a job does once its views are taken):
 * the view's colour and reasons stay; the colour frames, the decoder's planes and the range
 * image read as zeros where the platform gives pages back; the colour made again from the
 * frames read back into a restored view (scan_begin_colour, the model's path for [colour]
 * method = fit) is the view's, to the byte; and the next view, whose buffers come back as
 * zeros, is the same as one taken before. */
static void test_frames_given_back(void **state)
{
    (void)state;
    static struct test_rig t;
    static const struct mem_platform posix = {memory_posix_prefault, memory_posix_release};
    static uint8_t reason_a[HAL_MAX_PIXELS], rgb_a[HAL_MAX_PIXELS * 3];
    static float xyz_a[HAL_MAX_PIXELS * 3], normal_a[HAL_MAX_PIXELS * 3], conf_a[HAL_MAX_PIXELS];
    uint8_t *frames[COLOUR_MAX_FRAMES] = {0};
    mem_use(&posix);
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    assert_int_equal(test_rig_start(&t), 0);
    struct scan_view a, b;
    struct scan_view_info info;
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &a, &info), 0);
    test_rig_stop(&t);
    size_t n = (size_t)a.width * a.height;
    memcpy(reason_a, a.maps.reason, n);
    memcpy(rgb_a, a.rgb, n * 3);
    memcpy(conf_a, a.confidence, n * sizeof(float));
    memcpy(xyz_a, a.range.xyz_mm, n * 3 * sizeof(float));
    memcpy(normal_a, a.range.normal, n * 3 * sizeof(float));
    uint8_t *white = malloc(n * 3);
    assert_non_null(white);
    memcpy(white, a.white_rgb, n * 3);
    unsigned kept = 0;
    for (uint32_t k = 0; k < COLOUR_MAX_FRAMES; k++)
        if (a.lights[k] != NULL) {
            assert_non_null(frames[k] = malloc(n * 3));
            memcpy(frames[k], a.lights[k], n * 3), kept++;
        }
    assert_true(kept >= 5); /* config/sim.ini: multi, four lights and their dark frame */
    assert_false(all_zero(t.scan->decode.white, n));
    assert_false(all_zero(a.lights[COLOUR_FRAME_LIGHT0], n * 3));

    scan_release_frames(t.scan);
    assert_memory_equal(reason_a, a.maps.reason, n);
    assert_memory_equal(rgb_a, a.rgb, n * 3);
    int heard = all_zero(a.lights[COLOUR_FRAME_LIGHT0], n * 3);
#ifdef __x86_64__ /* make test-arm64: qemu-user may take madvise and do nothing */
    assert_true(heard);
#endif
    if (heard) {
        assert_true(all_zero(t.scan->decode.white, n));
        assert_true(all_zero(t.scan->colour_rgb, n * 3));
        assert_true(all_zero(a.range.xyz_mm, n * 3 * sizeof(float))); /* restored, if needed */
    }
    /* the range image again, as the model restores a view (range.bin's points) */
    struct scan_view r;
    struct scan_view_fill fill;
    assert_int_equal(scan_restore_view(t.scan, a.width, a.height, a.angle_mdeg, a.range.valid_count,
                                       a.colour_method, &r, &fill),
                     0);
    for (size_t i = 0; i < n; i++)
        if (reason_a[i] == SCAN_VALID) {
            memcpy(&fill.xyz_mm[3 * i], &xyz_a[3 * i], 3 * sizeof(float));
            memcpy(&fill.normal[3 * i], &normal_a[3 * i], 3 * sizeof(float));
        }
    assert_ptr_equal(r.range.xyz_mm, a.range.xyz_mm);
    assert_ptr_equal(r.range.normal, a.range.normal);

    /* the colour again from its frames read back, as the model's fit path does */
    memset(a.rgb, 0, n * 3);
    assert_int_equal(scan_begin_colour(t.scan, &t.cfg.scan, &t.calib), 0);
    for (uint32_t k = 0; k < COLOUR_MAX_FRAMES; k++)
        if (frames[k] != NULL)
            assert_int_equal(scan_feed_light_frame(t.scan, k, frames[k]), 0);
    assert_int_equal(scan_feed_white_colour(t.scan, white), 0);
    scan_attach_colour(t.scan, &a);
    assert_int_equal(scan_recolour(&t.cfg.scan.colour, NULL, &t.calib, &a, NULL), 0);
    assert_memory_equal(a.rgb, rgb_a, n * 3);
    assert_memory_equal(a.confidence, conf_a, n * sizeof(float));

    /* the next view, into buffers given back, as the first */
    scan_release_frames(t.scan);
    assert_int_equal(test_rig_start(&t), 0);
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &b, &info), 0);
    test_rig_stop(&t);
    assert_memory_equal(b.maps.reason, reason_a, n);
    assert_memory_equal(b.rgb, rgb_a, n * 3);
    for (size_t i = 0; i < n; i++)
        if (reason_a[i] == SCAN_VALID)
            assert_memory_equal(&xyz_a[3 * i], &b.range.xyz_mm[3 * i], 3 * sizeof(float));
    print_message("%u valid pixels, %u colour frames given back (%s) and the view the same\n",
                  (unsigned)info.valid_points, kept, heard ? "read as zeros" : "not heard");
    for (uint32_t k = 0; k < COLOUR_MAX_FRAMES; k++)
        free(frames[k]);
    free(white);
    mem_use(NULL);
}

/* A view context whose colour frames' memory is lent (scan_use_light_frames(NULL), as a job
 * does once its fusion begins: app/job.c): a method that reads colour frames cannot begin a
 * view, take the lights or be fed a frame, and no buffer is handed out for one; the method none
 * still decodes; the frames given back, the same view is taken as before. */
static void test_colour_frames_lent(void **state)
{
    (void)state;
    static struct test_rig t;
    static uint8_t rgb[HAL_MAX_PIXELS * 3];
    static uint8_t reason_a[HAL_MAX_PIXELS];
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    struct scan_params none = t.cfg.scan;
    none.colour.method = COLOUR_NONE;
    struct gray_layout layout;
    scan_layout(&t.cfg.scan, &t.calib, &layout);
    uint32_t first_light = gray_layout_count(&layout);
    struct scan_light_probe probe;
    assert_true(scan_light_frame_count(&t.cfg.scan, &t.calib) >= 5);
    assert_int_equal(test_rig_start(&t), 0);
    struct scan_view a, b;
    struct scan_view_info info;
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &a, &info), 0);
    size_t n = (size_t)a.width * a.height;
    memcpy(reason_a, a.maps.reason, n);

    scan_use_light_frames(t.scan, NULL);
    assert_int_equal(scan_begin_colour(t.scan, &t.cfg.scan, &t.calib), -EINVAL);
    assert_int_equal(scan_begin_view(t.scan, &t.cfg.scan, &t.calib), -EINVAL);
    assert_null(scan_frame_buffer(t.scan, first_light));
    assert_int_equal(scan_feed_light_frame(t.scan, COLOUR_FRAME_LIGHT0, rgb), -EINVAL);
    assert_int_equal(scan_probe_lights(t.scan, &t.hal, &t.cfg.scan, &t.calib, &probe), -EINVAL);
    assert_true(test_rig_dark());
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &b, &info),
                     -EINVAL);
    assert_true(test_rig_dark());
    /* no colour frames to read: the view is decoded as before */
    assert_int_equal(scan_take_view(t.scan, &t.hal, &none, &t.calib, 0, NULL, &b, &info), 0);
    assert_memory_equal(b.maps.reason, reason_a, n);

    assert_ptr_equal(scan_job_views(), t.scan); /* the job's memory given back to it */
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &b, &info), 0);
    test_rig_stop(&t);
    assert_memory_equal(b.maps.reason, reason_a, n);
    assert_non_null(b.lights[COLOUR_FRAME_LIGHT0]);
}

/* The volume needs no zeroed memory: a job gives it the memory its views' colour frames were in
 * (app/job.c). The bunny's view fused into a volume of zeros and into one of other bytes, its
 * holes filled, closed watertight, meshed and its mesh's holes closed, gives the same mesh.ply,
 * mesh.obj, mesh.stl and mesh.glb to the byte. */
static void test_volume_begins_on_any_bytes(void **state)
{
    (void)state;
    static struct test_rig t;
    static const char *const names[] = {"mesh.ply", "mesh.obj", "mesh.stl", "mesh.glb"};
    struct fusion_volume *vol = &test_volume;
    struct hal_storage st;
    storage_posix_init(&st);
    assert_int_equal(system("mkdir -p build/test_view/zeros build/test_view/bytes"), 0);
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    assert_int_equal(test_rig_start(&t), 0);
    struct scan_view view;
    struct scan_view_info info;
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info),
                     0);
    test_rig_stop(&t);
    struct frame_xform pose;
    frame_object_from_camera(&t.calib, view.angle_mdeg, &pose);
    struct mesh_summary ms[2];
    for (int bytes = 0; bytes < 2; bytes++) {
        char path[4][64];
        for (int k = 0; k < 4; k++)
            snprintf(path[k], sizeof(path[k]), "build/test_view/%s/%s", bytes ? "bytes" : "zeros",
                     names[k]);
        memset(vol, bytes ? 0xa5 : 0, sizeof(*vol));
        uint32_t filled, inside;
        struct mesh_hole_report holes;
        assert_int_equal(fusion_begin(vol, &t.cfg.fusion), 0);
        assert_int_equal(scan_fuse_view(vol, NULL, &t.calib, &view, &pose), 0);
        assert_int_equal(fusion_fill_holes(vol, 10.0, &filled), 0);
        assert_int_equal(fusion_close_watertight(vol, 10.0, 1, &inside), 0);
        assert_int_equal(fusion_mesh_prepare(vol, 0.01, &ms[bytes]), 0);
        assert_int_equal(fusion_mesh_fill_holes(vol, 10.0, &holes), 0);
        assert_int_equal(fusion_write_ply(vol, &st, path[0]), 0);
        assert_int_equal(fusion_write_obj(vol, &st, path[1]), 0);
        assert_int_equal(fusion_write_stl(vol, &st, path[2]), 0);
        assert_int_equal(fusion_write_glb(vol, &st, path[3], NULL), 0);
    }
    assert_true(ms[0].kept_vertices > 10000);
    for (int k = 0; k < 4; k++) {
        char a[64], b[64];
        snprintf(a, sizeof(a), "build/test_view/zeros/%s", names[k]);
        snprintf(b, sizeof(b), "build/test_view/bytes/%s", names[k]);
        assert_true(test_files_equal(a, b));
    }
    print_message("%u vertices, the same mesh from a volume of zeros and of 0xa5 bytes\n",
                  (unsigned)ms[0].kept_vertices);
}

/* Once a job has lent its colour frames to the volume (job_lend_frames, as the fusion begins), a
 * view whose range.bin has gone is not decoded again (the decoder's colour frames are the
 * volume's now): one error, naming the file and what makes the model again. */
static void test_no_view_decoded_once_frames_lent(void **state)
{
    (void)state;
    static struct test_rig t;
    const char *dir = "build/test_view/lent";
    struct scan_job_opts opts;
    struct job j;
    struct scan_view view;
    struct scan_view_info info;
    memset(&opts, 0, sizeof(opts));
    assert_int_equal(system("rm -rf build/test_view/lent && mkdir -p build/test_view/lent"), 0);
    assert_int_equal(test_rig_start_box(&t), 0);
    job_init(&j, &t.hal, &t.cfg, &t.calib, &opts, dir);
    j.views = 1;
    job_lend_frames(&j);
    test_log_clear();
    assert_int_equal(job_load_range(&j, dir, 0, &view, &info), -EIO);
    assert_true(test_log_one_error("view_000/range.bin"));
    assert_true(test_log_has("cannot be decoded again now; 'scanner process build/test_view/lent"));
    assert_null(t.scan->light); /* a colour frame is refused, not written over the volume */
    test_rig_stop(&t);
    assert_ptr_equal(scan_job_views(), t.scan); /* the next job's frames again */
    assert_non_null(t.scan->light);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_bunny),
        cmocka_unit_test(test_sphere_at_the_cameras_limit),
        cmocka_unit_test(test_dark_paint_with_hdr_and_highlights),
        cmocka_unit_test(test_interreflection_gray_against_xor04),
        cmocka_unit_test(test_blocked_decoder_matches_reference),
        cmocka_unit_test(test_threads_decode_the_same),
        cmocka_unit_test(test_object_beyond_the_volume_counted),
        cmocka_unit_test(test_volume_off_the_axis_fuses_the_same),
        cmocka_unit_test(test_fewer_inverses),
        cmocka_unit_test(test_two_scan_contexts_are_independent),
        cmocka_unit_test(test_frames_given_back),
        cmocka_unit_test(test_colour_frames_lent),
        cmocka_unit_test(test_volume_begins_on_any_bytes),
        cmocka_unit_test(test_no_view_decoded_once_frames_lent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

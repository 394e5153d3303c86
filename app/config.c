/* The scanner's config and calibration files: key tables, cross-checks, and their documentation. */
#define _POSIX_C_SOURCE 200809L
#include "config.h"
#include "calib_file.h"
#include "gray.h"
#include "ini_schema.h"

#include <errno.h>
#include <libgen.h>
#include <limits.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define C(member) offsetof(struct app_config, member)
#define SZ(member) sizeof(((struct app_config *)0)->member)
#define U32(sec, key, member, lo, hi, def, doc)                                                    \
    {                                                                                              \
        sec, key, INI_U32, C(member), 0, lo, hi, 0, def, NULL, doc, NULL, NULL                     \
    }
#define LIM(sec, key, member, lo, hi, limit, def, doc)                                             \
    {                                                                                              \
        sec, key, INI_U32, C(member), 0, lo, hi, limit, def, NULL, doc, NULL, NULL                 \
    }
#define F64(sec, key, member, lo, hi, def, doc)                                                    \
    {                                                                                              \
        sec, key, INI_F64, C(member), 0, lo, hi, 0, def, NULL, doc, NULL, NULL                     \
    }
#define STR(sec, key, member, def, doc)                                                            \
    {                                                                                              \
        sec, key, INI_STR, C(member), SZ(member), 0, 0, 0, def, NULL, doc, NULL, NULL              \
    }
#define ENUM(sec, key, member, choices, def, doc)                                                  \
    {                                                                                              \
        sec, key, INI_ENUM, C(member), SZ(member), 0, 0, 0, def, choices, doc, NULL, NULL          \
    }
#define GPIO(key, which)                                                                           \
    {                                                                                              \
        "gpio", key, INI_LINE, C(gpio.line[which]), 0, -1, 1023, 0, "-1", NULL,                    \
            "line offset on the chip, or the line's name (gpioinfo); -1 = not wired", NULL, NULL   \
    }

static const struct ini_key config_keys[] = {
    ENUM("camera", "backend", camera_backend, "sim|v4l2|libcamera", NULL,
         "which camera backend drives the camera (only those built in are accepted)"),
    STR("camera", "device", camera.device, "/dev/video0", "V4L2 device path or libcamera id"),
    LIM("camera", "width", camera.width, 16, HAL_MAX_WIDTH, HAL_FRAME_LIMIT_ADVICE, NULL,
        "frame width in pixels"),
    LIM("camera", "height", camera.height, 16, HAL_MAX_HEIGHT, HAL_FRAME_LIMIT_ADVICE, NULL,
        "frame height in pixels"),
    ENUM("camera", "pixel_format", camera_pixel_format, "rgb24|yuyv|grey", "rgb24",
         "pixel format requested from the device (converted to RGB)"),
    U32("camera", "exposure_us", camera.exposure_us, 10, 10000000, NULL,
        "fixed exposure time (auto exposure is always off)"),
    U32("camera", "gain_milli", camera.gain_milli, 1000, 64000, "1000",
        "fixed analogue gain, 1000 = unity"),
    U32("camera", "drop_frames", camera.drop_frames, 0, 16, "1",
        "stale frames dropped after a light or pattern change"),
    U32("camera", "frame_timeout_ms", camera.frame_timeout_ms, 10, 600000, "2000",
        "a capture that gets no frame in this time fails (and is retried)"),
    U32("camera", "red_gain_milli", camera.red_gain_milli, 100, 16000, "1000",
        "fixed white-balance gain of red (libcamera; auto white balance is off)"),
    U32("camera", "blue_gain_milli", camera.blue_gain_milli, 100, 16000, "1000",
        "fixed white-balance gain of blue (libcamera)"),
    F64("camera", "read_noise_dn", scan.read_noise_dn, 0, 50, "1.5",
        "read noise (standard deviation, grey levels) of the camera: the decoder's bit threshold"),
    F64("camera", "electrons_per_dn", scan.electrons_per_dn, 0, 10000, "20",
        "electrons per grey level (sets the shot noise; 0: read noise only)"),
    U32("camera", "binning", camera.binning, 1, HAL_MAX_BINNING, "1",
        "the sensor runs at binning x width by binning x height and each binning x binning "
        "block becomes one pixel (their mean): a sensor larger than the compiled frame limit, "
        "with less noise; width and height (and the calibration) are the binned frame's"),
    U32("camera", "capture_retries", scan.capture_retries, 0, 10, "2",
        "extra tries of a capture that timed out or came back corrupt"),
    U32("projector", "settle_us", scan.pattern_settle_us, 0, 1000000, "20000",
        "wait after switching pattern before capturing"),
    ENUM("projector", "backend", projector_backend, "gpio|drm", "gpio",
         "gpio: a projector with its own stored sequence, stepped by the trigger and reset "
         "lines; drm: a projector on the board's HDMI output, each pattern drawn by the scanner "
         "and shown by a page flip (libdrm)"),
    STR("projector", "device", projector_device, "/dev/dri/card0",
        "the DRM device of the HDMI output (backend = drm)"),
    U32("projector", "trigger_pulse_us", scan.trigger_pulse_us, 1, 100000, "100",
        "width of the trigger and reset pulses"),
    LIM("lights", "count", light_count, 0, HAL_MAX_LIGHTS, "", "0",
        "white lights wired to light_0 .. light_N-1"),
    U32("scan", "views", views, 1, 360, "1", "views per pass (a turn of the table)"),
    U32("scan", "passes", passes, 1, 2, "1",
        "2: after the first turn the person lays the object another way (on its side) and the "
        "table turns again; the second pass is found in the first and both make one model (the "
        "parts one pass cannot see: the underside, deep folds)"),
    {"scan", "exposures_us", INI_LIST, C(exposures_us), SCAN_MAX_EXPOSURES, 10, 10000000, 0, "",
     NULL,
     "HDR patterns: every pattern captured at each of these exposures (ascending, one of them "
     "[camera] exposure_us), per pixel the longest whose white frame is not saturated; for "
     "objects with dark and shiny parts. Empty: [camera] exposure_us alone",
     NULL, NULL},
    U32("scan", "auto_exposure", auto_exposure, 0, 1, "1",
        "1: before the first view a white and a black frame show whether most of what the "
        "projector lights is too dark to decode (white minus black under min_contrast_dn); if "
        "so, and exposures_us is not in the file, every pattern is also taken at the exposure "
        "that lifts it (HDR); and where the colour reads single-light frames and [colour] "
        "light_exposure_us is not in the file, a dark frame and each light alone choose their "
        "exposure; what is chosen is said in the log and kept in the scan's config.ini. 0: the "
        "exposure as set"),
    F64("scan", "start_angle_deg", start_angle_deg, -360, 360, "0", "turntable angle of view 0"),
    U32("scan", "min_contrast_dn", scan.min_contrast_dn, 1, 255, "10",
        "white minus black (grey levels) below this: too dark to decode, flagged 'dark'"),
    U32("scan", "shadow_contrast_dn", scan.shadow_contrast_dn, 0, 254, "5",
        "white minus black at or below this: no projector light, flagged 'shadow'"),
    U32("scan", "min_bit_diff_dn", scan.min_bit_diff_dn, 0, 254, "4",
        "a pattern and its inverse differing by at most this make an ambiguous bit"),
    U32("scan", "max_ambiguous_bits", scan.max_ambiguous_bits, 0, 16, "1",
        "a pixel with more unclear bits than this is valid only where its neighbourhood "
        "resolves them (1 allows a column edge)"),
    U32("scan", "max_unclear_bits", scan.max_unclear_bits, 0, 8, "4",
        "a pixel with more unclear bits than this is flagged 'low_contrast' (not resolved)"),
    F64("scan", "bit_noise_sigmas", scan.bit_noise_sigmas, 0, 20, "2",
        "a bit is unclear when |pattern - inverse| is within this many standard deviations of "
        "the camera's noise at the pixel's contrast (and within min_bit_diff_dn)"),
    U32("scan", "saturation_dn", scan.saturation_dn, 1, 255, "250",
        "a channel at or above this is saturated; a bit whose pattern and inverse are both "
        "saturated is unclear, a black frame saturated flags the pixel 'saturated'"),
    U32("scan", "max_column_jump", scan.max_column_jump, 0, 1000, "3",
        "neighbours whose columns differ by at most this agree"),
    U32("scan", "min_consistent_neighbours", scan.min_consistent_neighbours, 0, 8, "3",
        "a pixel needs this many agreeing neighbours (of 8), else 'inconsistent'"),
    F64("scan", "max_depth_jump_mm", scan.max_depth_jump_mm, 0.01, 1000, "3",
        "a larger depth step between neighbours is a surface boundary (for normals)"),
    ENUM("scan", "code", code, "gray|xor04", "gray",
         "how the projector codes its columns: Gray code, or XOR-04 (every coarse bit projected "
         "XOR the 4-pixel stripes; for concave and shiny objects whose light bounces onto "
         "themselves; the projector's stored sequence changes: scanner patterns)"),
    U32("scan", "decode_rows", scan.decode_rows, 0, 1, "0",
        "1: code projector rows too (twice the patterns; rows must agree with neighbours)"),
    U32("scan", "inverse_bits", scan.inverse_bits, 0, 16, "0",
        "the finest bits of each coordinate projected with their inverse; a coarser bit is read "
        "against the mean of white and black, a frame fewer each (0: every bit has its "
        "inverse; the projector's stored sequence changes: scanner patterns)"),
    U32("scan", "threads", scan.threads, 0, HAL_MAX_THREADS, "0",
        "the cores a view's decoding is split across (0: all there are); the result is the same "
        "to the byte however many"),
    U32("scan", "refine", scan.refine, 0, 1, "1",
        "1: interpolate the projector column across each stripe (sub-stripe refinement)"),
    U32("scan", "normal_radius_px", scan.normal_radius_px, 1, 32, "4",
        "normals are estimated across up to this many pixels on each side"),
    STR("scan", "calibration", calibration_file, NULL,
        "calibration file, relative to this config file"),
    STR("output", "dir", output_dir, "scans",
        "where scans go: each scan without --out gets a "
        "new folder here named by when it began (UTC, YYYY-MM-DD_HHMMSS), and 'latest' links "
        "to the newest; relative to the working directory"),
    F64("output", "max_hole_mm", max_hole_mm, 0, 100, "0",
        "holes in the model narrower than this are closed (on the mesh: each boundary loop "
        "whose extent is under this, fanned from its centre; with watertight also in the "
        "volume first); 0: none, nothing invented"),
    U32("output", "watertight", watertight, 0, 1, "0",
        "1: close the model for printing: at the table plane, and what no camera saw under a "
        "surface or behind a hole up to max_hole_mm is solid (needs max_hole_mm > 0)"),
    ENUM("output", "frame_format", frame_format_name, "zstd|png|pnm", "zstd",
         "how frames are kept: zstd (frame_NN.pgm.zst / .ppm.zst, a PGM or PPM compressed; "
         "'zstd -d' gives the image), png, or pnm (uncompressed PGM/PPM); make bench compares "
         "their size and time"),
    ENUM("output", "keep_frames", keep_frames_name, "all|colour|none", "all",
         "which camera frames a scan keeps: all (scanner process can decode and colour again), "
         "colour (the colour frames, not the stripe patterns), or none; each view's range image "
         "(range.bin) is kept in every case, so process can still register and fuse again. A scan "
         "or resume the disk cannot hold as kept (about 33, 21 or 7 bytes a camera pixel a view) "
         "is refused before it starts"),
    U32("output", "texture", texture, 0, 1, "1",
        "1: the model's colour also as a texture at the camera's resolution (texture.png, with "
        "mesh.obj's mesh.mtl and inside mesh.glb); the vertices take the views' colour either "
        "way, in the same pass"),
    F64("output", "texel_mm", texel_mm, 0, 10, "0",
        "a texel's edge on the object; 0: a camera pixel's at the turntable's axis (larger when "
        "the surface does not fit the compiled texture size, said)"),
    F64("output", "min_fragment_share", min_fragment_share, 0, 1, "0.01",
        "floating pieces of the mesh with fewer triangles than this share of the largest piece "
        "are left out of every output (0: keep every piece)"),
    STR("gpio", "chip", gpio.chip, "gpiochip0", "GPIO chip name or path"),
    GPIO("projector_enable", HAL_GPIO_PROJECTOR_ENABLE),
    GPIO("projector_trigger", HAL_GPIO_PROJECTOR_TRIGGER),
    GPIO("projector_reset", HAL_GPIO_PROJECTOR_RESET),
    GPIO("light_0", HAL_GPIO_LIGHT_0 + 0),
    GPIO("light_1", HAL_GPIO_LIGHT_0 + 1),
    GPIO("light_2", HAL_GPIO_LIGHT_0 + 2),
    GPIO("light_3", HAL_GPIO_LIGHT_0 + 3),
    GPIO("light_4", HAL_GPIO_LIGHT_0 + 4),
    GPIO("light_5", HAL_GPIO_LIGHT_0 + 5),
    GPIO("light_6", HAL_GPIO_LIGHT_0 + 6),
    GPIO("light_7", HAL_GPIO_LIGHT_0 + 7),
    ENUM("turntable", "transport", turntable.transport, "tcp|rtu", "tcp",
         "Modbus transport to the turntable controller"),
    STR("turntable", "host", turntable.host, "127.0.0.1", "Modbus TCP host"),
    U32("turntable", "port", turntable.port, 0, 65535, "1502",
        "Modbus TCP port (0: any free port, for the simulated controller only)"),
    STR("turntable", "device", turntable.device, "/dev/ttyUSB0", "Modbus RTU serial device"),
    U32("turntable", "baud", turntable.baud, 1200, 1000000, "19200", "Modbus RTU baud rate"),
    ENUM("turntable", "parity", turntable.parity, "none|even|odd", "even", "Modbus RTU parity"),
    U32("turntable", "unit_id", turntable.unit_id, 1, 247, "1", "Modbus unit / slave id"),
    U32("turntable", "response_timeout_ms", turntable.response_timeout_ms, 10, 60000, "500",
        "Modbus response timeout"),
    U32("turntable", "byte_timeout_ms", turntable.byte_timeout_ms, 1, 10000, "50",
        "Modbus timeout between the bytes of a reply"),
    U32("turntable", "retries", turntable.retries, 0, 10, "3",
        "extra tries of a request with no valid reply (flush, and reconnect on TCP, in between)"),
    U32("turntable", "poll_interval_ms", turntable.poll_interval_ms, 1, 10000, "50",
        "status polling interval while the table moves"),
    F64("turntable", "angle_accuracy_deg", registration.angle_accuracy_deg, 0.001, 45, "1",
        "how far the table's reported angle may be from the true one (one standard deviation): "
        "the registration keeps the table's angle where the object's shape cannot fix the turn "
        "(a sphere, a cylinder, any surface of revolution about the axis) or where neighbouring "
        "views share too little of it to outweigh this"),
    F64("turntable", "axis_accuracy_mm", registration.axis_accuracy_mm, 0.001, 100, "0.1",
        "how far the calibrated axis may be from the true one, across it (one standard "
        "deviation): the registration moves the axis only as far as the views' pairs outweigh "
        "this (never looser than a third of [registration] max_axis_shift_mm), and only where "
        "moving it fits the views better than their own errors explain (else the calibrated "
        "axis is kept and said: docs/architecture.md)"),
    F64("turntable", "axis_tilt_accuracy_deg", registration.axis_tilt_accuracy_deg, 0.001, 45,
        "0.033",
        "how far the calibrated axis's direction may be from the true one (one standard "
        "deviation; never looser than a third of [registration] max_axis_tilt_deg)"),
    U32("turntable", "move_timeout_ms", turntable.move_timeout_ms, 100, 600000, "30000",
        "a move or homing must finish within this"),
    F64("turntable", "speed_dps", turntable.speed_dps, 0.1, 6000, "30", "table speed, deg/s"),
    F64("turntable", "accel_dps2", turntable.accel_dps2, 0.1, 6000, "60",
        "table acceleration, deg/s^2"),
    U32("turntable", "tolerance_mdeg", turntable.tolerance_mdeg, 0, 10000, "10",
        "the reached angle must be this close to the target"),
    U32("turntable", "settle_ms", turntable.settle_ms, 0, 60000, "300",
        "wait after a move before capturing"),
    ENUM("colour", "method", colour_method, "none|single|uniform|multi|fit", "none",
         "intrinsic colour: none (raw projector-lit colour), single (projector only, Jost eq. 4), "
         "uniform (all lights), multi (each light alone, eq. 6), fit (reflectance parameters: "
         "diffuse colour per point, a specular lobe per material cluster, from every light and "
         "view; docs/colour.md)"),
    U32("colour", "clusters", scan.colour.clusters, 1, REFLECT_MAX_CLUSTERS, "4",
        "fit: material clusters at most (k-means on the diffuse colour), each with its own "
        "specular lobe"),
    ENUM("colour", "ca", colour_ca, "channel|pixel|albedo", "albedo",
         "ambient + black offset from the dark frame: one value per channel, per pixel, or per "
         "channel as an offset plus the ambient light times the pixel's albedo (fitted over the "
         "object; dark paint reflects little of the ambient light)"),
    U32("colour", "all_lights_exposure_us", scan.colour.all_lights_exposure_us, 0, 10000000, "0",
        "exposure of the all-lights frame (0: [camera] exposure_us); a dark frame is taken at it "
        "too"),
    {"colour", "light_exposure_us", INI_LIST, C(light_exposure_us), 1, 0, 10000000, 0, "", NULL,
     "exposure of each single-light frame (0: [camera] exposure_us); a dark frame is taken at "
     "it too. Empty: [camera] exposure_us, or with [scan] auto_exposure the exposure a dark "
     "frame and each light alone before the first view call for (multi and fit: the brightest "
     "light's 95th percentile brought to 95% of saturation_dn, at most 33 ms, a frame at 30 "
     "fps), said in the log and kept in the scan's config.ini",
     NULL, NULL},
    U32("colour", "bracket", scan.colour.bracket, 0, 64, "0",
        "each light is also taken at this many times its exposure (with a dark frame at it); "
        "multi reads each pixel in the longer frame where no channel saturates there, so dark "
        "paint gets signal above the noise (0 or 1: one exposure)"),
    F64("colour", "shadow_ratio", scan.colour.shadow_ratio, 0, 1, "0.25",
        "multi: a light whose albedo estimate at a pixel is below this share of the best "
        "unhighlighted light's is taken as shadowed there (light from other surfaces only)"),
    F64("colour", "min_cos", scan.colour.min_cos, 0, 1, "0.2",
        "light at a lower cos(incidence) is not used (it would amplify noise)"),
    /* 10 and 4: a plastic's or a metal's sheen spreads 30 deg and more from the mirror
     * direction; with 40 and 2 (a light weighs 0.5 at 11 deg) dark paint under it came out
     * L* 27 for 20 (make eval: docs/colour.md) */
    F64("colour", "ke", scan.colour.ke, 1, 10000, "10", "highlight rejection exponent ke (eq. 6)"),
    F64("colour", "ko", scan.colour.ko, 0, 100, "4", "highlight rejection exponent ko (eq. 6)"),
    F64("colour", "shadow_dn", scan.colour.shadow_dn, 0, 255, "6",
        "a light's frame within this of Ca: the light is shadowed there"),
    U32("colour", "falloff", scan.colour.falloff, 0, 1, "1",
        "1: compensate the inverse-square falloff from each calibrated source"),
    F64("colour", "reference_mm", scan.colour.reference_mm, 1, 100000, "600",
        "distance at which the falloff compensation is 1"),
    {"colour", "white_scale", INI_VEC, C(scan.colour.white_scale), 3, 1e-6, 1000, 0,
     "0.00392157, 0.00392157, 0.00392157", NULL,
     "per channel, grey levels to albedo: a white surface comes out as 1 (from scanner "
     "calibrate-white; the default 1/255 keeps grey levels)",
     NULL, NULL},
    U32("registration", "icp", registration.enabled, 0, 1, "1",
        "1: register all views jointly (turns about one axis, re-estimated; each view's angle "
        "free); 0: keep the turntable's angles and the calibrated axis"),
    U32("registration", "sample_stride", registration.sample_stride, 1, 64, "4",
        "registration keeps every n-th pixel of a view in x and y (more when many views would "
        "not fit REG_MAX_CELLS)"),
    U32("registration", "iterations", registration.iterations, 0, 100, "20",
        "Gauss-Newton steps of the joint registration, each with new pairs"),
    F64("registration", "max_pair_mm", registration.max_pair_mm, 0.01, 100, "1.5",
        "points farther apart do not couple (the first steps search 4 times as far)"),
    F64("registration", "max_normal_deg", registration.max_normal_deg, 0, 180, "20",
        "normals differing more do not couple"),
    U32("registration", "use_colour", registration.use_colour, 0, 1, "1",
        "1: colours must agree too (multi-feature matching), and a pair whose shapes agree but "
        "whose paint does not marks where the object slid along its faces (0: such a slide "
        "goes unseen)"),
    F64("registration", "max_colour_dn", registration.max_colour_dn, 0, 255, "40",
        "largest per-channel colour difference of a coupled pair"),
    F64("registration", "max_correction_deg", registration.max_correction_deg, 0, 45, "3",
        "a view's angle may move this far from the angle the table reported; a solution "
        "beyond it is refused (the turntable's poses are kept)"),
    F64("registration", "max_axis_shift_mm", registration.max_axis_shift_mm, 0, 100, "3",
        "the axis may move this far from the calibrated one"),
    F64("registration", "max_axis_tilt_deg", registration.max_axis_tilt_deg, 0, 45, "1",
        "the axis may tilt this far from the calibrated one"),
    F64("registration", "min_coupled_share", registration.min_coupled_share, 0, 1, "0.2",
        "two neighbouring views coupling less of their overlap do not match (the object "
        "moved?): the scan fails and names the view instead of fusing a wrong pose"),
    F64("fusion", "voxel_mm", fusion.voxel_mm, 0.1, 20, "1.0", "edge of a fusion voxel"),
    F64("fusion", "radius_mm", fusion.radius_mm, 5, 2000, "100",
        "the fused volume spans this radius around the turntable axis (grown to hold a wider "
        "object: fit_volume)"),
    F64("fusion", "bottom_mm", fusion.bottom_mm, -1000, 1000, "-3",
        "lowest height fused (table surface = 0)"),
    F64("fusion", "top_mm", fusion.top_mm, -1000, 2000, "165",
        "highest height fused (grown to hold a taller object: fit_volume)"),
    U32("fusion", "fit_volume", fusion.fit_volume, 0, 1, "1",
        "1: the volume grows past radius_mm and top_mm to hold what the registered views saw "
        "(within this build's limits; moved off the axis towards an object placed far from it "
        "where a volume about the axis would be beyond them), and says so; 0: they cut the "
        "object, and the scan says what was left out"),
    F64("fusion", "truncation_mm", fusion.truncation_mm, 0.1, 100, "2.5",
        "signed distances are clamped to +- this"),
    F64("fusion", "max_weight", fusion.max_weight, 1, 60, "50", "a voxel's weight stops here"),
    U32("fusion", "edge_fade_px", fusion.edge_fade_px, 0, 200, "12",
        "view weights ramp up over this many pixels from the view's edge"),
    F64("fusion", "min_weight", fusion.min_weight, 0, 1, "0.05",
        "pixels weighing less (grazing, far) are not fused"),
    ENUM("sim", "object", sim.object, "sphere|cylinder|can|box|torus|corner|groove|mesh", "sphere",
         "simulated object"),
    STR("sim", "mesh_file", sim.mesh_file, "", "PLY mesh for object = mesh, relative to this file"),
    STR("sim", "rig", sim.rig_file, "",
        "the true rig the simulator renders with (a calibration file, relative to this file); "
        "empty: the scan's calibration, so the firmware knows the rig exactly"),
    F64("sim", "object_height_mm", sim.object_height_mm, 1, 1000, "150",
        "object height after scaling (sphere: diameter)"),
    {"sim", "second_pass_pose", INI_VEC, C(sim.second_pass_pose_deg), 3, -360, 360, 0, "90, 0, 30",
     NULL,
     "[scan] passes = 2: how the simulated person lays the object for the second pass, as "
     "object_pose (degrees about x, then y, then z, then stood on the table)",
     NULL, NULL},
    ENUM("sim", "person", sim.person, "auto|asked", "auto",
         "how the simulated person meets the scanner's questions (the second pass of [scan] "
         "passes = 2, each step of scanner calibrate): auto, does what is asked at once; asked, "
         "does it, and the scanner waits for the answer as on a real rig (Enter, or the "
         "page's Continue)"),
    {"sim", "object_pose", INI_VEC, C(sim.object_pose_deg), 3, -360, 360, 0, "0, 0, 0", NULL,
     "the object turned by these angles (degrees, about x, then y, then z) before it is stood on "
     "the table at its lowest point: 90, 0, 0 lays an upright object on its side (a second pass)",
     NULL, NULL},
    {"sim", "object_offset_mm", INI_VEC, C(sim.object_offset_mm), 2, -200, 200, 0, "0, 0", NULL,
     "where the object stands on the table (x, y in mm, the table's frame at angle 0): a person "
     "seldom puts it on the axis; 0, 0 centres it there",
     NULL, NULL},
    {"sim", "slip_mm", INI_VEC, C(sim.slip_mm), 3, -100, 100, 0, "0, 0, 0", NULL,
     "the object slips on the table by this much (mm, table frame at angle 0) once the table "
     "has reached slip_at_deg: a registration that must fail and name the view",
     NULL, NULL},
    F64("sim", "slip_at_deg", sim.slip_at_deg, 0, 360, "180",
        "the table angle from which the object has slipped by slip_mm"),
    U32("sim", "segments", sim.segments, 8, 4096, "384", "tessellation of analytic shapes"),
    ENUM("sim", "material", sim.material, "lambert|phong|merl|burley", "lambert",
         "reflectance model (burley: Burley's diffuse, as Blender's Principled BSDF has it)"),
    STR("sim", "merl_file", sim.merl_file, "", "MERL/ABC table (CSV), relative to this file"),
    STR("sim", "merl_name", sim.merl_name, "", "material name in the MERL/ABC table"),
    F64("sim", "phong_ks", sim.phong_ks, 0, 100, "0.5", "Phong specular strength ks"),
    F64("sim", "phong_ke", sim.phong_ke, 1, 10000, "40", "Phong shininess ke"),
    F64("sim", "burley_roughness", sim.burley_roughness, 0, 1, "1",
        "material = burley: the diffuse's roughness (0 darker, 1 brighter at grazing light)"),
    ENUM("sim", "albedo_pattern", sim.albedo_pattern, "patches|uniform|image", "patches",
         "painted patches and stripes (with a very dark one), one colour, or albedo_image "
         "wrapped round the object (its columns once round the axis, its rows top to bottom)"),
    STR("sim", "albedo_image", sim.albedo_image, "",
        "albedo_pattern = image: a PNG photograph (sRGB; white is albedo 0.9), relative to this "
        "file"),
    {"sim", "albedo", INI_VEC, C(sim.albedo), 3, 0, 1, 0, "0.8, 0.8, 0.8", NULL,
     "albedo for albedo_pattern = uniform", NULL, NULL},
    U32("sim", "seed", sim.seed, 0, 4294967295.0, "1", "noise seed (runs are repeatable)"),
    U32("sim", "table_angle_error_mdeg", sim.table_angle_error_mdeg, 0, 10000, "0",
        "the table ends each move up to this far from the angle it reports (open-loop stepper)"),
    F64("sim", "placement_jitter_mm", sim.placement_jitter_mm, 0, 50, "0",
        "scanner calibrate: the simulated person stands each board up to this far (mm, along and "
        "across the table) from where the step asks, by the seed (a person repeating the "
        "procedure never places a board the same way twice); 0: exactly there"),
    F64("sim", "placement_jitter_deg", sim.placement_jitter_deg, 0, 20, "0",
        "... and leaning up to this much more or less than asked (degrees)"),
    F64("sim", "black_offset_dn", sim.black_offset_dn, 0, 255, "51",
        "camera black offset (Jost et al. Table 1: 51)"),
    F64("sim", "ambient_dn", sim.ambient_dn, 0, 255, "3", "indirect light on a white surface"),
    F64("sim", "read_noise_dn", sim.read_noise_dn, 0, 50, "1.5", "Gaussian read noise (sigma)"),
    F64("sim", "electrons_per_dn", sim.electrons_per_dn, 0.1, 10000, "20",
        "sensor conversion gain, sets the shot noise"),
    F64("sim", "projector_intensity_dn", sim.projector_intensity_dn, 0, 10000, "170",
        "white Lambertian facing the projector at the reference distance, in grey levels"),
    F64("sim", "projector_black_level", sim.projector_black_level, 0, 1, "0.01",
        "light the projector leaks in its black"),
    F64("sim", "projector_blur_px", sim.projector_blur_px, 0, 1, "0.6",
        "projector defocus, as a box width in projector pixels"),
    F64("sim", "camera_blur_px", sim.camera_blur_px, 0, 8, "0",
        "camera lens blur, the sigma of a Gaussian point spread in camera pixels"),
    F64("sim", "frame_rate_hz", sim.frame_rate_hz, 0, 1000, "30",
        "the camera streams frames at this rate, as a real sensor does: a capture lets the frame "
        "in flight go by ([camera] drop_frames) and waits for the next to end (and readout_us), "
        "so the simulated scan takes the real rig's time; 0: a frame takes only its exposure"),
    U32("sim", "readout_us", sim.readout_us, 0, 1000000, "0",
        "from the end of a frame to its arrival (ISP, USB transfer)"),
    U32("sim", "jpeg_quality", sim.jpeg_quality, 0, 100, "0",
        "1..100: each frame is JPEG-compressed at this quality and decoded (libjpeg), as a "
        "camera's JPEG stream; 0: off"),
    U32("sim", "bounce_samples", sim.bounce_samples, 0, 1024, "0",
        "interreflection: the projector's light bounced once between surfaces, sampled in this "
        "many directions per point (concave objects); 0: direct light only"),
    F64("sim", "light_intensity_dn", sim.light_intensity_dn, 0, 10000, "120",
        "like projector_intensity_dn, for each white light"),
    F64("sim", "light_diffuser_mm", sim.light_diffuser_mm, 0, 1000, "0",
        "radius of each light's diffuser (softbox); 0: a point light"),
    F64("sim", "reference_distance_mm", sim.reference_distance_mm, 1, 100000, "600",
        "distance at which the intensities above hold (inverse-square falloff)"),
    U32("sim", "reference_exposure_us", sim.reference_exposure_us, 1, 10000000, "10000",
        "exposure at which the intensities above hold"),
    ENUM("calibrate", "board", calibrate.board, "chessboard|charuco", "chessboard",
         "the printed board: a plain chessboard (seen whole) or ChArUco (seen in part)"),
    U32("calibrate", "squares_x", calibrate.squares_x, 3, 33, "9", "squares across the board"),
    U32("calibrate", "squares_y", calibrate.squares_y, 3, 33, "7", "squares down the board"),
    F64("calibrate", "square_mm", calibrate.square_mm, 1, 500, "20",
        "side of a square as printed (measure it: the scale of every result)"),
    F64("calibrate", "marker_mm", calibrate.marker_mm, 1, 500, "15",
        "ChArUco: side of a marker, smaller than a square"),
    ENUM("calibrate", "dictionary", calibrate.dictionary, "4x4_50|4x4_100|5x5_50|5x5_100|6x6_250",
         "5x5_100", "ChArUco: the ArUco dictionary of the markers"),
    F64("calibrate", "margin_mm", calibrate.margin_mm, 0, 200, "10",
        "white border around the squares; the sheet's bottom edge sits on the plate's"),
    F64("calibrate", "board_thickness_mm", calibrate.board_thickness_mm, 0, 100, "3",
        "plate the sheet is glued to (the table's height is found from the board's bottom edge)"),
    STR("calibrate", "placements", calibrate.placements, "0, 35, -25, 0@75, 0@-75, 25@75, 25@-75",
        "the board's placements, comma-separated: each a tilt from upright in degrees (leaning "
        "back; 90: lying flat), optionally @ an offset in mm to the camera's right ('0@70')"),
    U32("calibrate", "turns", calibrate.turns, 1, 32, "5", "table angles per board placement"),
    F64("calibrate", "turn_step_deg", calibrate.turn_step_deg, 0, 90, "15",
        "between those angles, centred on 0 (the board must stay in view)"),
    F64("calibrate", "sphere_diameter_mm", calibrate.sphere_diameter_mm, 1, 500, "60",
        "the matte white sphere (lights) and the verification ball"),
    F64("calibrate", "sphere_offset_mm", calibrate.sphere_offset_mm, 0, 300, "50",
        "how far from the table's centre the sphere is placed"),
    U32("calibrate", "sphere_turns", calibrate.sphere_turns, 0, 32, "6",
        "table angles of the sphere, evenly round (0: lights are not calibrated)"),
    U32("calibrate", "projector_width", calibrate.projector_width, 1, HAL_MAX_PROJECTOR_WIDTH,
        "1024", "projector columns, when no calibration file exists yet"),
    U32("calibrate", "projector_height", calibrate.projector_height, 1, HAL_MAX_PROJECTOR_HEIGHT,
        "768", "projector rows, when no calibration file exists yet"),
    U32("calibrate", "min_corners", calibrate.min_corners, 6, 1024, "12",
        "fewer corners found in an image: the image is not used"),
    U32("calibrate", "fix_k3", calibrate.fix_k3, 0, 1, "1",
        "1: the sixth-order radial term stays 0 (ordinary lenses; avoids over-fitting)"),
    F64("calibrate", "max_camera_rms_px", calibrate.max_camera_rms_px, 0.01, 100, "0.5",
        "a camera reprojection RMS above this refuses the calibration"),
    F64("calibrate", "max_projector_rms_px", calibrate.max_projector_rms_px, 0.01, 100, "1",
        "a projector reprojection RMS above this refuses the calibration"),
    F64("calibrate", "max_sigma_centre_px", calibrate.max_sigma_centre_px, 0.01, 1000, "5",
        "a principal point (camera or projector) less certain than this (one standard "
        "deviation) writes the calibration flagged weak, saying what to capture next"),
    F64("calibrate", "max_sigma_focal_share", calibrate.max_sigma_focal_share, 1e-5, 1, "0.005",
        "a focal length less certain than this share of itself flags it weak"),
    F64("calibrate", "max_sigma_translation_mm", calibrate.max_sigma_translation_mm, 0.001, 1000,
        "1", "the camera -> projector translation less certain than this flags it weak"),
    F64("calibrate", "max_sigma_rotation_deg", calibrate.max_sigma_rotation_deg, 1e-4, 90, "0.05",
        "the camera -> projector rotation less certain than this flags it weak"),
    F64("calibrate", "max_depth_error_mm", calibrate.max_depth_error_mm, 1e-4, 100, "0.05",
        "a depth error predicted at the working volume's edge (the lenses', the pose's and the "
        "axis's uncertainty carried to a scan) above this flags it weak: about the scanner's own "
        "mean error on the demo rig, which such a calibration could add again"),
};

#undef C
#undef SZ
static enum hal_pixel_format pixel_format_of(const char *s)
{
    return strcmp(s, "yuyv") == 0   ? HAL_PIX_YUYV
           : strcmp(s, "grey") == 0 ? HAL_PIX_GREY
                                    : HAL_PIX_RGB24;
}

/* [calibrate] placements: the board's tilts, comma-separated. */
static int parse_placements(struct calib_settings *c, const char *path, char *err, size_t len)
{
    const char *p = c->placements;
    c->placement_count = 0;
    while (*p != '\0') {
        char *end;
        double tilt = strtod(p, &end);
        if (end == p || tilt < -60.0 || tilt > 90.0) {
            snprintf(err, len,
                     "%s: [calibrate] placements: '%s': each placement is a tilt from upright "
                     "in degrees, -60..90",
                     path, c->placements);
            return -EINVAL;
        }
        if (c->placement_count == CALIB_MAX_PLACEMENTS) {
            snprintf(err, len, "%s: [calibrate] placements: more than %u", path,
                     (unsigned)CALIB_MAX_PLACEMENTS);
            return -EINVAL;
        }
        double offset = 0.0;
        p = end + strspn(end, " \t");
        if (*p == '@') {
            offset = strtod(p + 1, &end);
            if (end == p + 1 || fabs(offset) > 300.0) {
                snprintf(err, len,
                         "%s: [calibrate] placements: '%s': after '@' an offset in mm, -300..300",
                         path, c->placements);
                return -EINVAL;
            }
            p = end + strspn(end, " \t");
        }
        c->offset_mm[c->placement_count] = offset;
        c->tilt_deg[c->placement_count++] = tilt;
        if (*p == ',')
            p++;
        else if (*p != '\0') {
            snprintf(err, len, "%s: [calibrate] placements: '%s': numbers separated by commas",
                     path, c->placements);
            return -EINVAL;
        }
    }
    return 0;
}

/* @p name as the config file @p config_path names it: relative to its directory unless
 * absolute. @retval 0 @retval -ENAMETOOLONG */
static int path_beside(const char *config_path, const char *name, char *out, size_t len)
{
    char dir_buf[HAL_MAX_PATH];
    snprintf(dir_buf, sizeof(dir_buf), "%s", config_path);
    int n = name[0] == '/' ? snprintf(out, len, "%s", name)
                           : snprintf(out, len, "%s/%s", dirname(dir_buf), name);
    return n < 0 || (size_t)n >= len ? -ENAMETOOLONG : 0;
}

int config_check_files(const struct app_config *cfg, char *err, size_t err_len)
{
    /* the simulator's own files, where the config makes it read them */
    const struct {
        const char *key, *name;
        int used;
    } files[] = {
        {"mesh_file", cfg->sim.mesh_file, strcmp(cfg->sim.object, "mesh") == 0},
        {"merl_file", cfg->sim.merl_file, strcmp(cfg->sim.material, "merl") == 0},
        {"albedo_image", cfg->sim.albedo_image, strcmp(cfg->sim.albedo_pattern, "image") == 0},
    };
    if (strcmp(cfg->camera_backend, "sim") != 0)
        return 0;
    for (size_t k = 0; k < sizeof(files) / sizeof(files[0]); k++) {
        char joined[HAL_MAX_PATH * 2 + 2];
        if (!files[k].used || files[k].name[0] == '\0')
            continue;
        int rc = path_beside(cfg->path, files[k].name, joined, sizeof(joined));
        if (rc == 0 && access(joined, R_OK) != 0)
            rc = -errno;
        if (rc != 0) {
            snprintf(err, err_len, "%s: [sim] %s: %s: %s", cfg->path, files[k].key, joined,
                     strerror(-rc));
            return rc;
        }
    }
    return 0;
}

/* [sim] rig: the geometry the simulator renders with, loaded now so that a bad file is named at
 * start like the calibration is. */
static int load_sim_rig(struct app_config *cfg, const char *path, char *err, size_t err_len)
{
    if (cfg->sim.rig_file[0] == '\0')
        return 0;
    char joined[HAL_MAX_PATH * 2 + 2], why[512];
    int rc = path_beside(path, cfg->sim.rig_file, joined, sizeof(joined));
    if (rc == 0)
        rc = calib_load(&cfg->sim.rig, joined, cfg->light_count, why, sizeof(why));
    else
        snprintf(why, sizeof(why), "path too long");
    if (rc != 0) {
        snprintf(err, err_len, "%s: [sim] rig: %s", path, why);
        return rc;
    }
    cfg->sim.has_rig = 1;
    return 0;
}

/* [scan] exposures_us into the scan's exposures: ascending, and holding the camera's own (the
 * view's colour is taken at it); and [colour] light_exposure_us (empty: 0). */
static int config_exposures(struct app_config *cfg, const char *path, char *err, size_t err_len)
{
    const struct ini_list *l = &cfg->exposures_us;
    int has_camera = l->count == 0;
    for (unsigned k = 0; k < l->count; k++) {
        if (k > 0 && l->value[k] <= l->value[k - 1]) {
            snprintf(err, err_len, "%s: [scan] exposures_us: must be ascending", path);
            return -EINVAL;
        }
        cfg->scan.exposures_us[k] = (uint32_t)l->value[k];
        has_camera |= cfg->scan.exposures_us[k] == cfg->camera.exposure_us;
    }
    if (!has_camera) {
        snprintf(err, err_len,
                 "%s: [scan] exposures_us: must include [camera] exposure_us (%u), at which the "
                 "view's colour is taken",
                 path, (unsigned)cfg->camera.exposure_us);
        return -EINVAL;
    }
    cfg->scan.exposure_count = l->count;
    cfg->scan.colour.light_exposure_us =
        cfg->light_exposure_us.count > 0 ? (uint32_t)cfg->light_exposure_us.value[0] : 0u;
    return 0;
}

/* What config_load_offline gives the keys that only drive the rig, when they are left out. */
static const struct ini_fallback offline_fallbacks[] = {
    {"camera", "backend", "sim"},
    {"camera", "exposure_us", "10000"},
    {"scan", "calibration", ""},
};

/* config_load, or with @p offline config_load_offline. */
static int load(struct app_config *cfg, const char *path, int offline, char *err, size_t err_len)
{
    memset(cfg, 0, sizeof(*cfg));
    int rc = ini_schema_load_with(
        config_keys, sizeof(config_keys) / sizeof(config_keys[0]), cfg, path,
        offline ? offline_fallbacks : NULL,
        offline ? sizeof(offline_fallbacks) / sizeof(offline_fallbacks[0]) : 0, err, err_len);
    if (rc != 0)
        return rc;
    snprintf(cfg->path, sizeof(cfg->path), "%s", path);
    cfg->camera.pixel_format = pixel_format_of(cfg->camera_pixel_format);
    cfg->scan.width = cfg->camera.width;
    static const char *const methods[] = {"none", "single", "uniform", "multi", "fit"};
    for (uint32_t k = 0; k < 5; k++)
        if (strcmp(cfg->colour_method, methods[k]) == 0)
            cfg->scan.colour.method = k;
    cfg->scan.colour.ca = strcmp(cfg->colour_ca, "pixel") == 0    ? COLOUR_CA_PIXEL
                          : strcmp(cfg->colour_ca, "albedo") == 0 ? COLOUR_CA_ALBEDO
                                                                  : COLOUR_CA_CHANNEL;
    cfg->scan.code = strcmp(cfg->code, "xor04") == 0 ? GRAY_CODE_XOR04 : GRAY_CODE_GRAY;
    cfg->frame_format = strcmp(cfg->frame_format_name, "png") == 0   ? SCAN_FRAMES_PNG
                        : strcmp(cfg->frame_format_name, "pnm") == 0 ? SCAN_FRAMES_PNM
                                                                     : SCAN_FRAMES_ZSTD;
    cfg->keep_frames = strcmp(cfg->keep_frames_name, "colour") == 0 ? KEEP_FRAMES_COLOUR
                       : strcmp(cfg->keep_frames_name, "none") == 0 ? KEEP_FRAMES_NONE
                                                                    : KEEP_FRAMES_ALL;
    cfg->scan.colour.saturation_dn = cfg->scan.saturation_dn;
    cfg->scan.colour.exposure_us = cfg->camera.exposure_us;
    cfg->scan.colour.gain_milli = cfg->camera.gain_milli;
    if (cfg->scan.colour.method >= COLOUR_UNIFORM && cfg->light_count == 0) {
        snprintf(err, err_len, "%s: [colour] method: '%s' needs lights ([lights] count is 0)", path,
                 cfg->colour_method);
        return -EINVAL;
    }
    if (cfg->scan.colour.method == COLOUR_FIT && cfg->keep_frames == KEEP_FRAMES_NONE) {
        snprintf(err, err_len,
                 "%s: [colour] method: 'fit' reads each view's colour frames again once all are "
                 "in: [output] keep_frames must keep them (all or colour), not none",
                 path);
        return -EINVAL;
    }
    cfg->scan.height = cfg->camera.height;
    if (cfg->camera.binning > 1 && strcmp(cfg->camera_backend, "sim") == 0) {
        snprintf(err, err_len,
                 "%s: [camera] binning: the simulator renders at the calibration's size; binning "
                 "is for a real camera (v4l2 or libcamera)",
                 path);
        return -EINVAL;
    }
    if ((rc = config_exposures(cfg, path, err, err_len)) != 0)
        return rc;
    if (cfg->scan.shadow_contrast_dn >= cfg->scan.min_contrast_dn) {
        snprintf(err, err_len, "%s: [scan] shadow_contrast_dn: %u must be below min_contrast_dn %u",
                 path, (unsigned)cfg->scan.shadow_contrast_dn, (unsigned)cfg->scan.min_contrast_dn);
        return -EINVAL;
    }
    uint32_t dims[3];
    if (fusion_dims(&cfg->fusion, dims) != 0) {
        snprintf(err, err_len,
                 "%s: [fusion] voxel_mm: a %.2f mm grid over radius %.0f mm and heights %.0f..%.0f "
                 "mm exceeds the compiled limit (%u per axis, %u voxels: FUSION_MAX_* in "
                 "hal/include/hal_limits.h)",
                 path, cfg->fusion.voxel_mm, cfg->fusion.radius_mm, cfg->fusion.bottom_mm,
                 cfg->fusion.top_mm, FUSION_MAX_DIM, FUSION_MAX_VOXELS);
        return -EINVAL;
    }
    if (strcmp(cfg->sim.object, "mesh") == 0 && cfg->sim.mesh_file[0] == '\0') {
        snprintf(err, err_len, "%s: [sim] mesh_file: required when object = mesh", path);
        return -EINVAL;
    }
    if (strcmp(cfg->sim.material, "merl") == 0 &&
        (cfg->sim.merl_file[0] == '\0' || cfg->sim.merl_name[0] == '\0')) {
        snprintf(err, err_len,
                 "%s: [sim] merl_name: merl_file and merl_name are required when "
                 "material = merl",
                 path);
        return -EINVAL;
    }
    if (cfg->calibration_file[0] == '\0' && !offline) {
        snprintf(err, err_len, "%s: [scan] calibration: empty: name the rig's calibration file",
                 path);
        return -EINVAL;
    }
    /* The calibration file is named relative to the config file (none: offline, a guess). */
    if (cfg->calibration_file[0] != '\0') {
        char joined[sizeof(cfg->calibration_file)];
        if (path_beside(path, cfg->calibration_file, joined, sizeof(joined)) != 0) {
            snprintf(err, err_len, "%s: [scan] calibration: path too long", path);
            return -EINVAL;
        }
        memcpy(cfg->calibration_file, joined, sizeof(joined));
    }
    rc = parse_placements(&cfg->calibrate, path, err, err_len);
    if (rc != 0)
        return rc;
    const struct calib_settings *cb = &cfg->calibrate;
    uint32_t captures = cb->placement_count * cb->turns + cb->sphere_turns;
    if (captures > CALIB_MAX_VIEWS) {
        snprintf(err, err_len,
                 "%s: [calibrate] turns: %u placements x %u turns + %u sphere turns are %u "
                 "captures, more than the %u a calibration directory holds (CALIB_MAX_VIEWS)",
                 path, (unsigned)cb->placement_count, (unsigned)cb->turns,
                 (unsigned)cb->sphere_turns, (unsigned)captures, (unsigned)CALIB_MAX_VIEWS);
        return -EINVAL;
    }
    if (strcmp(cb->board, "chessboard") == 0 && cb->squares_x == cb->squares_y) {
        snprintf(err, err_len,
                 "%s: [calibrate] squares_y: a chessboard's squares_x and squares_y must differ "
                 "(a square one reads the same turned by 90 degrees)",
                 path);
        return -EINVAL;
    }
    if (strcmp(cb->board, "charuco") == 0 && cb->marker_mm >= cb->square_mm) {
        snprintf(err, err_len, "%s: [calibrate] marker_mm: %g must be below square_mm %g", path,
                 cb->marker_mm, cb->square_mm);
        return -EINVAL;
    }
    if (cfg->views * cfg->passes > REG_MAX_VIEWS) {
        snprintf(err, err_len,
                 "%s: [scan] views: %u views x %u passes exceed the %u a scan holds "
                 "(REG_MAX_VIEWS)",
                 path, (unsigned)cfg->views, (unsigned)cfg->passes, (unsigned)REG_MAX_VIEWS);
        return -EINVAL;
    }
    if (cfg->watertight && cfg->max_hole_mm <= 0.0) {
        snprintf(err, err_len,
                 "%s: [output] watertight: a closed model needs max_hole_mm > 0, the widest hole "
                 "to close (e.g. 10)",
                 path);
        return -EINVAL;
    }
    return load_sim_rig(cfg, path, err, err_len);
}

int config_load(struct app_config *cfg, const char *path, char *err, size_t err_len)
{
    return load(cfg, path, 0, err, err_len);
}

int config_load_offline(struct app_config *cfg, const char *path, char *err, size_t err_len)
{
    return load(cfg, path, 1, err, err_len);
}

void config_print_doc(FILE *out)
{
    fprintf(out,
            "# Configuration reference\n\n"
            "Generated by `scanner config-doc` (`make docs`); a test fails when it is stale.\n\n"
            "A scan is driven by an INI file (`scanner scan --config FILE`) that names a "
            "calibration file. Any unknown section or key, a value that is not a number or "
            "not one of the listed words, a value out of range, a key set twice, a missing "
            "required key, or a size above the compiled buffer limits "
            "(`hal/include/hal_limits.h`) stops the scanner before it touches any device, "
            "with a message naming the file, the line and the key, for example:\n\n"
            "    config/rig.ini:12: [lights] count: 9 exceeds the compiled limit 8 "
            "(see hal/include/hal_limits.h)\n\n"
            "Relative paths (`calibration`, `mesh_file`, `merl_file`) are resolved against "
            "the directory of the file that names them; `[output] dir` against the working "
            "directory.\n\n"
            "## Scan config (e.g. `config/sim.ini`)\n");
    ini_schema_print_doc(config_keys, sizeof(config_keys) / sizeof(config_keys[0]), out);
    fprintf(out, "\n## Calibration file (e.g. `config/sim-calib.ini`)\n\nAll geometry is in the "
                 "camera frame (x right, y down, z forward), in millimetres.\n");
    calib_print_doc(out);
}

/* How a scan's views were taken: what its frames are and where the table stood. */
struct plan_key {
    const char *section, *key;
    double (*get)(const struct app_config *c, unsigned i);
    unsigned count;                                  /* a list: exposures_us */
    const char *(*text)(const struct app_config *c); /* a word (an enum), to say it as written */
};
#define PLAN_GET(name, expr)                                                                       \
    static double plan_##name(const struct app_config *c, unsigned i)                              \
    {                                                                                              \
        (void)i;                                                                                   \
        return (double)(expr);                                                                     \
    }
PLAN_GET(views, c->views)
PLAN_GET(passes, c->passes)
PLAN_GET(start, c->start_angle_deg)
PLAN_GET(width, c->camera.width)
PLAN_GET(height, c->camera.height)
PLAN_GET(binning, c->camera.binning)
PLAN_GET(exposure, c->camera.exposure_us)
PLAN_GET(gain, c->camera.gain_milli)
PLAN_GET(hdr_count, c->scan.exposure_count)
PLAN_GET(code, c->scan.code)
PLAN_GET(rows, c->scan.decode_rows)
PLAN_GET(inverse_bits, c->scan.inverse_bits)
PLAN_GET(lights, c->light_count)
/* 0: the camera's exposure (docs/config.md): compared as the exposure the frames get */
PLAN_GET(all_lights, c->scan.colour.all_lights_exposure_us ? c->scan.colour.all_lights_exposure_us
                                                           : c->camera.exposure_us)
PLAN_GET(light_exp, c->scan.colour.light_exposure_us ? c->scan.colour.light_exposure_us
                                                     : c->camera.exposure_us)
PLAN_GET(bracket, c->scan.colour.bracket)
PLAN_GET(method, c->scan.colour.method)
static const char *plan_code_text(const struct app_config *c)
{
    return c->code;
}
static const char *plan_method_text(const struct app_config *c)
{
    return c->colour_method;
}
static double plan_hdr(const struct app_config *c, unsigned i)
{
    return i < c->scan.exposure_count ? (double)c->scan.exposures_us[i] : 0.0;
}

void config_adopt_chosen(struct app_config *now, const struct app_config *taken)
{
    if (!now->auto_exposure)
        return;
    if (now->scan.exposure_count == 0 && taken->scan.exposure_count > 0 &&
        !now->exposures_us.given) {
        memcpy(now->scan.exposures_us, taken->scan.exposures_us, sizeof(now->scan.exposures_us));
        now->scan.exposure_count = taken->scan.exposure_count;
    }
    if (!now->light_exposure_us.given && taken->light_exposure_us.given)
        now->scan.colour.light_exposure_us = taken->scan.colour.light_exposure_us;
}

int config_plan_differs(const struct app_config *taken, const struct app_config *now, int capturing,
                        char *what, size_t what_len)
{
    static const struct plan_key keys[] = {
        {"scan", "views", plan_views, 1, NULL},
        {"scan", "passes", plan_passes, 1, NULL},
        {"scan", "start_angle_deg", plan_start, 1, NULL},
        {"camera", "width", plan_width, 1, NULL},
        {"camera", "height", plan_height, 1, NULL},
        {"camera", "binning", plan_binning, 1, NULL},
        {"camera", "exposure_us", plan_exposure, 1, NULL},
        {"camera", "gain_milli", plan_gain, 1, NULL},
        {"scan", "exposures_us (count)", plan_hdr_count, 1, NULL},
        {"scan", "exposures_us", plan_hdr, SCAN_MAX_EXPOSURES, NULL},
        {"scan", "code", plan_code, 1, plan_code_text},
        {"scan", "decode_rows", plan_rows, 1, NULL},
        {"scan", "inverse_bits", plan_inverse_bits, 1, NULL},
        {"lights", "count", plan_lights, 1, NULL},
        {"colour", "all_lights_exposure_us", plan_all_lights, 1, NULL},
        {"colour", "light_exposure_us", plan_light_exp, 1, NULL},
        {"colour", "bracket", plan_bracket, 1, NULL},
        {"colour", "method", plan_method, 1, plan_method_text},
    };
    size_t n = sizeof(keys) / sizeof(keys[0]) - (capturing ? 0 : 1); /* method: last */
    for (size_t k = 0; k < n; k++)
        for (unsigned i = 0; i < keys[k].count; i++) {
            double a = keys[k].get(taken, i), b = keys[k].get(now, i);
            if (a == b)
                continue;
            if (keys[k].text != NULL)
                snprintf(what, what_len, "[%s] %s = %s, not %s", keys[k].section, keys[k].key,
                         keys[k].text(taken), keys[k].text(now));
            else
                snprintf(what, what_len, "[%s] %s = %g, not %g", keys[k].section, keys[k].key, a,
                         b);
            return -EINVAL;
        }
    return 0;
}

void config_board(const struct app_config *cfg, struct board_config *out)
{
    *out = (struct board_config){.config_path = cfg->path,
                                 .camera_backend = cfg->camera_backend,
                                 .camera = &cfg->camera,
                                 .gpio = &cfg->gpio,
                                 .turntable = &cfg->turntable,
                                 .scan = &cfg->scan,
                                 .projector_backend = cfg->projector_backend,
                                 .projector_device = cfg->projector_device,
                                 .sim = &cfg->sim};
}

/* Config and calibration errors name file, line and key; nothing is accepted silently. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "board.h"
#include "config.h"
#include "job.h"
#include "scan.h"

#define DIR "build/test_config"
static struct app_config cfg;
static char err[512];

static const char *base =
    "[camera]\nbackend = sim\nwidth = 1280\nheight = 960\nexposure_us = 10000\n"
    "[scan]\ncalibration = ../../config/sim-calib.ini\n";

static const char *write_file(const char *name, const char *text)
{
    static char path[256];
    mkdir("build", 0755);
    mkdir(DIR, 0755);
    snprintf(path, sizeof(path), "%s/%s", DIR, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

/* Load base + @p extra and expect failure with @p expect in the message. */
static void expect_error(const char *extra, const char *expect)
{
    char text[2048];
    snprintf(text, sizeof(text), "%s%s", base, extra);
    const char *path = write_file("bad.ini", text);
    err[0] = '\0';
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), -EINVAL);
    if (strstr(err, expect) == NULL)
        fail_msg("expected '%s' in '%s'", expect, err);
}

static void test_good_config_and_defaults(void **state)
{
    (void)state;
    const char *path = write_file("good.ini", base);
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), 0);
    assert_int_equal(cfg.camera.width, 1280);
    assert_int_equal(cfg.scan.width, 1280);
    assert_int_equal(cfg.scan.min_contrast_dn, 10); /* default */
    assert_int_equal(cfg.gpio.line[HAL_GPIO_LIGHT_0].offset, -1);
    assert_string_equal(cfg.gpio.line[HAL_GPIO_LIGHT_0].name, "");
    assert_string_equal(cfg.calibration_file, DIR "/../../config/sim-calib.ini");
    struct scan_calib calib;
    assert_int_equal(calib_load(&calib, cfg.calibration_file, 4, err, sizeof(err)), 0);
    assert_int_equal(scan_check(&cfg.scan, &calib, err, sizeof(err)), 0);
}

/* The issue and many users write [color]: the same section as [colour], still checked. */
static void test_color_spelling(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof(text), "%s[color]\nmethod = single\nlight_exposure_us = 5000\n", base);
    assert_int_equal(config_load(&cfg, write_file("color.ini", text), err, sizeof(err)), 0);
    assert_int_equal(cfg.scan.colour.method, COLOUR_SINGLE);
    assert_int_equal(cfg.scan.colour.light_exposure_us, 5000);
    assert_int_equal(cfg.scan.colour.exposure_us, 10000); /* the camera's, for the dark frame */
    expect_error("[color]\nmethod = rainbow\n", "[colour] method");
}

static void test_errors_name_file_line_and_key(void **state)
{
    (void)state;
    expect_error("exposur_us = 5\n", DIR "/bad.ini:8: [scan] exposur_us: unknown key");
    expect_error("[camra]\nwidth = 5\n", "bad.ini:9: [camra] width: unknown section 'camra'");
    expect_error("[sim]\nseed = abc\n", "bad.ini:9: [sim] seed: 'abc' is not a whole number");
    expect_error("[scan]\nmin_contrast_dn = 300\n",
                 "bad.ini:9: [scan] min_contrast_dn: 300 is out of range 1..255");
    expect_error("[turntable]\nangle_accuracy_deg = 0\n",
                 "bad.ini:9: [turntable] angle_accuracy_deg: 0 is out of range");
    expect_error("[turntable]\naxis_accuracy_mm = -0.1\n",
                 "bad.ini:9: [turntable] axis_accuracy_mm: -0.1 is out of range");
    expect_error("[turntable]\naxis_accuracy_mm = nan\n",
                 "bad.ini:9: [turntable] axis_accuracy_mm:");
    expect_error("[turntable]\naxis_tilt_accuracy_deg = 90\n",
                 "bad.ini:9: [turntable] axis_tilt_accuracy_deg: 90 is out of range");
    expect_error("[turntable]\naxis_tilt_accuracy_deg = 0.1 deg\n",
                 "bad.ini:9: [turntable] axis_tilt_accuracy_deg:");
    expect_error("[camera]\npixel_format = bgr\n",
                 "bad.ini:9: [camera] pixel_format: 'bgr' is not one of rgb24|yuyv|grey");
    expect_error("[sim]\nalbedo = 0.5, 0.5\n", "bad.ini:9: [sim] albedo: '0.5, 0.5' is not a list");
    expect_error("[sim]\nseed = 1.5\n", "[sim] seed: '1.5' is not a whole number");
    expect_error("[sim]\nobject_offset_mm = 30\n",
                 "bad.ini:9: [sim] object_offset_mm: '30' is not a list of 2 numbers");
    expect_error("[sim]\nobject_offset_mm = 30, 20, 10\n", "'30, 20, 10' is not a list of 2");
    expect_error("[sim]\nobject_offset_mm = 30, nan\n", "'30, nan' is not a list of 2");
    expect_error("[sim]\nobject_offset_mm = 300, 0\n",
                 "[sim] object_offset_mm: 300 is out of range -200..200");
    /* a channel scaled by 0 is every colour black in it (a hand-edited white reference) */
    expect_error("[colour]\nwhite_scale = 0.004, 0, 0.004\n",
                 "bad.ini:9: [colour] white_scale: 0 is out of range 1e-06..1000");
    expect_error("[sim]\nmaterial = burly\n", "bad.ini:9: [sim] material: 'burly' is not one of");
    expect_error("[sim]\nmaterial = burley\nburley_roughness = 1.5\n",
                 "bad.ini:10: [sim] burley_roughness: 1.5 is out of range 0..1");
    expect_error("[sim]\nburley_roughness = -0\nburley_roughness = nan\n",
                 "bad.ini:10: [sim] burley_roughness:");
    expect_error("[scan]\nauto_exposure = 2\n",
                 "bad.ini:9: [scan] auto_exposure: 2 is out of range 0..1");
    /* the predicted depth error that flags a calibration weak: a positive length in mm */
    expect_error("[calibrate]\nmax_depth_error_mm = 0\n",
                 "bad.ini:9: [calibrate] max_depth_error_mm: 0 is out of range");
    expect_error("[calibrate]\nmax_depth_error_mm = 0.05 mm\n",
                 "bad.ini:9: [calibrate] max_depth_error_mm:");
    expect_error("[calibrate]\nmax_depth_error_mm = inf\n",
                 "bad.ini:9: [calibrate] max_depth_error_mm:");
    expect_error("garbage line\n", "bad.ini:8: syntax error");
    /* fit reads the colour frames again: a scan that keeps none could not make its model */
    expect_error("[lights]\ncount = 4\n[colour]\nmethod = fit\n[output]\nkeep_frames = none\n",
                 "[colour] method: 'fit' reads each view's colour frames again");
}

/* GPIO lines by offset or by the name the chip gives them (issue 5); anything else is refused. */
static void test_gpio_lines_by_offset_or_name(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof(text), "%s[gpio]\nlight_0 = GPIO17\nlight_1 = 5\nprojector_enable = -1\n",
             base);
    assert_int_equal(config_load(&cfg, write_file("lines.ini", text), err, sizeof(err)), 0);
    assert_string_equal(cfg.gpio.line[HAL_GPIO_LIGHT_0].name, "GPIO17");
    assert_int_equal(cfg.gpio.line[HAL_GPIO_LIGHT_0].offset, -1);
    assert_string_equal(cfg.gpio.line[HAL_GPIO_LIGHT_0 + 1].name, "");
    assert_int_equal(cfg.gpio.line[HAL_GPIO_LIGHT_0 + 1].offset, 5);
    assert_int_equal(cfg.gpio.line[HAL_GPIO_PROJECTOR_ENABLE].offset, -1);
    expect_error("[gpio]\nlight_2 = pin 7!\n",
                 "bad.ini:9: [gpio] light_2: 'pin 7!' is neither a line offset nor a line name");
    expect_error("[gpio]\nlight_2 = 2000\n", "bad.ini:9: [gpio] light_2: 2000 is out of range");
    expect_error("[gpio]\nlight_2 = 2.5\n", "[gpio] light_2: '2.5' is not a line offset");
}

static void test_duplicate_key(void **state)
{
    (void)state;
    const char *path = write_file("dup.ini", "[camera]\nwidth = 640\nwidth = 640\n");
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "dup.ini:3: [camera] width: set twice (first on line 2)"));
}

static void test_missing_required_key(void **state)
{
    (void)state;
    const char *path =
        write_file("missing.ini", "[camera]\nbackend = sim\nwidth = 640\nheight = 480\n");
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "missing.ini: [camera] exposure_us: required key is missing"));
}

static void test_width_over_limit(void **state)
{
    (void)state;
    const char *path = write_file("big.ini", "[camera]\nbackend = sim\nwidth = 4096\nheight = 960\n"
                                             "exposure_us = 10000\n[scan]\ncalibration = x.ini\n");
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "big.ini:3: [camera] width: 4096 exceeds the compiled limit 2048"));
    /* what to do instead: bin the sensor, or a build that takes its whole frame */
    assert_non_null(strstr(err, "limit 2048: a larger sensor: [camera] binning = 2, 3 or 4"));
    assert_non_null(strstr(err, "or the whole frame with 'make LIMITS=large' (up to 4928 x 3456"));
    /* a limit without such advice names the header that sets it */
    path = write_file("lights.ini", "[camera]\nbackend = sim\nwidth = 640\nheight = 480\n"
                                    "exposure_us = 10000\n[lights]\ncount = 9\n[scan]\n"
                                    "calibration = x.ini\n");
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "lights.ini:7: [lights] count: 9 exceeds the compiled limit 8 "
                                "(see hal/include/hal_limits.h)"));
    /* a calibration of a larger sensor, the same */
    struct scan_calib calib;
    path = write_file("bigcal.ini", "[camera]\nfx_px = 100\nfy_px = 100\ncx_px = 1\ncy_px = 1\n"
                                    "width = 4056\nheight = 3040\n");
    assert_int_equal(calib_load(&calib, path, 0, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "bigcal.ini:6: [camera] width: 4056 exceeds the compiled limit "
                                "2048: a larger sensor: [camera] binning"));
}

static void test_calibration_errors(void **state)
{
    (void)state;
    struct scan_calib calib;
    assert_int_equal(calib_load(&calib, DIR "/nope.ini", 0, err, sizeof(err)), -ENOENT);
    assert_non_null(strstr(err, "nope.ini: cannot open"));
    const char *path = write_file(
        "calib.ini", "[camera]\nfx_px = 100\nfy_px = 100\ncx_px = 1\ncy_px = 1\nwidth = 64\n"
                     "height = 64\n[projector]\nfx_px = 100\nfy_px = 100\ncx_px = 1\ncy_px = 1\n"
                     "width = 64\nheight = 64\nrotation = 1, 0, 0, 0, 1, 0, 0, 0, 0.9\n"
                     "translation_mm = 0, 0, 0\n[turntable]\naxis_point_mm = 0, 0, 500\n"
                     "axis_dir = 0, -1, 0\n");
    assert_int_equal(calib_load(&calib, path, 0, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "[projector] rotation: not a rotation matrix"));
    /* calibration for another camera size than configured */
    const char *good = write_file("good.ini", base);
    assert_int_equal(config_load(&cfg, good, err, sizeof(err)), 0);
    assert_int_equal(calib_load(&calib, cfg.calibration_file, 4, err, sizeof(err)), 0);
    calib.cam_width = 640;
    assert_int_equal(scan_check(&cfg.scan, &calib, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "calibration is for a 640x960 camera"));
    assert_non_null(strstr(err, "set them to 640x960, or calibrate the camera at 1280x960"));
    /* lights configured but not calibrated */
    assert_int_equal(calib_load(&calib, path, 2, err, sizeof(err)), -EINVAL);
}

/* A line longer than the parser's buffer is refused; before, the tail of a long comment was
 * read as a key of its own (start_angle_deg = 45 took effect). */
/* [scan] auto_exposure chooses the HDR exposures only where the file sets no exposures_us: the
 * loader says whether [scan] exposures_us was in the file (empty too, however spaced), not its
 * default, nor a comment; a file loaded after one that set it has its own. */
static void test_file_sets_a_key(void **state)
{
    (void)state;
    const char *path = write_file("good.ini", base);
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), 0);
    assert_int_equal(cfg.auto_exposure, 1); /* the default */
    assert_int_equal(cfg.exposures_us.given, 0);
    static const struct {
        const char *text;
        unsigned given, count;
    } cases[] = {{"exposures_us =\n", 1, 0},
                 {"exposures_us=10000, 20000\n", 1, 2},
                 {"exposures_us \t = 10000\n", 1, 1},
                 {"; exposures_us = 10000\n", 0, 0}};
    char text[1024];
    for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
        snprintf(text, sizeof(text), "%s%s", base, cases[k].text);
        assert_int_equal(config_load(&cfg, write_file("sets.ini", text), err, sizeof(err)), 0);
        assert_int_equal(cfg.exposures_us.given, cases[k].given);
        assert_int_equal(cfg.exposures_us.count, cases[k].count);
    }
    /* a loaded file that sets it, then one that does not: the flag is the second file's */
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), 0);
    assert_int_equal(cfg.exposures_us.given, 0);
    /* a link to a file that sets it is that file; a FIFO where it belongs is refused, not read */
    unlink(DIR "/sets-link");
    assert_int_equal(symlink("sets.ini", DIR "/sets-link"), 0);
    snprintf(text, sizeof(text), "%s%s", base, cases[0].text);
    write_file("sets.ini", text);
    assert_int_equal(config_load(&cfg, DIR "/sets-link", err, sizeof(err)), 0);
    assert_int_equal(cfg.exposures_us.given, 1);
    unlink(DIR "/sets-fifo");
    assert_int_equal(mkfifo(DIR "/sets-fifo", 0600), 0);
    assert_int_equal(config_load(&cfg, DIR "/sets-fifo", err, sizeof(err)), -EINVAL);
}

/* [colour] light_exposure_us: the loader says whether the file set it (empty: the camera's or
 * the lights' choice, [scan] auto_exposure), one number at most, named by file, line and key
 * when bad; what a scan chose is written after the file's own lines (job_chosen_lines) and read
 * back as the file's, so a resume or a re-processing takes it as set. */
static void test_light_exposure_given(void **state)
{
    (void)state;
    static const struct {
        const char *text;
        unsigned given;
        uint32_t us;
    } cases[] = {{"", 0, 0},
                 {"[colour]\nlight_exposure_us =\n", 1, 0},
                 {"[colour]\nlight_exposure_us = 0\n", 1, 0},
                 {"[colour]\nlight_exposure_us = 20000\n", 1, 20000}};
    char text[2048];
    for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
        snprintf(text, sizeof(text), "%s%s", base, cases[k].text);
        assert_int_equal(config_load(&cfg, write_file("light.ini", text), err, sizeof(err)), 0);
        assert_int_equal(cfg.light_exposure_us.given, cases[k].given);
        assert_int_equal(cfg.scan.colour.light_exposure_us, cases[k].us);
    }
    snprintf(text, sizeof(text), "%s[colour]\nlight_exposure_us = 10000, 20000\n", base);
    assert_int_equal(config_load(&cfg, write_file("light.ini", text), err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "light.ini:9: [colour] light_exposure_us"));
    snprintf(text, sizeof(text), "%s[colour]\nlight_exposure_us = -5\n", base);
    assert_int_equal(config_load(&cfg, write_file("light.ini", text), err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "light.ini:9: [colour] light_exposure_us"));
    /* chosen by the scan: kept after the file's lines, then the file's own */
    assert_int_equal(config_load(&cfg, write_file("light.ini", base), err, sizeof(err)), 0);
    char chosen[JOB_CHOSEN_LINES_MAX];
    assert_int_equal(job_chosen_lines(&cfg, chosen, sizeof(chosen)), 0);
    assert_string_equal(chosen, ""); /* nothing chosen */
    cfg.scan.colour.light_exposure_us = 19000;
    assert_int_equal(job_chosen_lines(&cfg, chosen, sizeof(chosen)), 0);
    assert_non_null(strstr(chosen, "\n[colour]\nlight_exposure_us = 19000\n"));
    char small[40];
    assert_int_equal(job_chosen_lines(&cfg, small, sizeof(small)), -EOVERFLOW);
    snprintf(text, sizeof(text), "%s%s", base, chosen);
    assert_int_equal(config_load(&cfg, write_file("light.ini", text), err, sizeof(err)), 0);
    assert_int_equal(cfg.light_exposure_us.given, 1);
    assert_int_equal(cfg.scan.colour.light_exposure_us, 19000);
    assert_int_equal(job_chosen_lines(&cfg, chosen, sizeof(chosen)), 0);
    assert_string_equal(chosen, ""); /* the file's now: not written twice */
}

static void test_overlong_line_refused(void **state)
{
    (void)state;
    char extra[512];
    int n = snprintf(extra, sizeof(extra), "; ");
    while (n < 250)
        extra[n++] = 'x';
    snprintf(extra + n, sizeof(extra) - (size_t)n, " start_angle_deg = 45\nviews = 8\n");
    expect_error(extra, "bad.ini:8: line longer than 198 characters");
}

/* Only a regular file of a sensible size is a config: /dev/zero, a FIFO and a directory each
 * get their own message at once (before, /dev/zero spun forever at 100% CPU, a directory was
 * "required key is missing"). */
static void test_not_a_regular_file(void **state)
{
    (void)state;
    err[0] = '\0';
    assert_int_equal(config_load(&cfg, "/dev/zero", err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "/dev/zero: not a regular file (a device, pipe or socket)"));
    assert_int_equal(config_load(&cfg, DIR, err, sizeof(err)), -EISDIR);
    assert_non_null(strstr(err, DIR ": not a regular file (a directory)"));
    unlink(DIR "/fifo");
    assert_int_equal(mkfifo(DIR "/fifo", 0600), 0);
    assert_int_equal(config_load(&cfg, DIR "/fifo", err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "fifo: not a regular file"));
    struct scan_calib calib;
    assert_int_equal(calib_load(&calib, "/dev/urandom", 0, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "/dev/urandom: not a regular file"));
}

/* An empty calibration name, and a calibration whose projector sits on the camera (a scan of
 * it "finished" with 0 points): each refused with its key. */
static void test_empty_calibration_and_zero_baseline(void **state)
{
    (void)state;
    const char *path =
        write_file("empty-calib.ini", "[camera]\nbackend = sim\nwidth = 1280\nheight = 960\n"
                                      "exposure_us = 10000\n[scan]\ncalibration =\n");
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "[scan] calibration: empty"));
    struct scan_calib calib;
    path = write_file(
        "no-baseline.ini",
        "[camera]\nfx_px = 100\nfy_px = 100\ncx_px = 1\ncy_px = 1\nwidth = 64\nheight = 64\n"
        "[projector]\nfx_px = 100\nfy_px = 100\ncx_px = 1\ncy_px = 1\nwidth = 64\n"
        "height = 64\nrotation = 1, 0, 0, 0, 1, 0, 0, 0, 1\ntranslation_mm = 0, 0, 0\n"
        "[turntable]\naxis_point_mm = 0, 0, 500\naxis_dir = 0, -1, 0\n");
    assert_int_equal(calib_load(&calib, path, 0, err, sizeof(err)), -EINVAL);
    assert_non_null(strstr(err, "[projector] translation_mm: the projector is 0.0 mm from the "
                                "camera"));
}

/* A calibration of another rig, or none: config/sim-calib.ini with one value changed. */
static int load_changed_calibration(const char *from, const char *to)
{
    static char text[8192];
    FILE *f = fopen("config/sim-calib.ini", "r");
    assert_non_null(f);
    size_t n = fread(text, 1, sizeof(text) - 1, f);
    fclose(f);
    text[n] = '\0';
    char *at = strstr(text, from), changed[8192];
    assert_non_null(at);
    snprintf(changed, sizeof(changed), "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
    struct scan_calib calib;
    err[0] = '\0';
    return calib_load(&calib, write_file("changed-calib.ini", changed), 4, err, sizeof(err));
}

/* Calibration values a lens cannot have are refused with their key (issue 28: cx_px = 99999
 * passed check-config; a distortion of +-100 made the scan fail with "did the object move?"). */
static void test_calibration_values_within_bounds(void **state)
{
    (void)state;
    assert_int_equal(load_changed_calibration("cx_px = 639.5", "cx_px = 639.5"), 0);
    assert_int_equal(load_changed_calibration("cx_px = 639.5", "cx_px = 99999"), -EINVAL);
    assert_non_null(
        strstr(err, "changed-calib.ini: [camera] cx_px: 99999.0 is off the 1280x960 image"));
    assert_int_equal(load_changed_calibration("cy_px = 479.5", "cy_px = -3"), -EINVAL);
    assert_non_null(strstr(err, "[camera] cy_px: -3.0 is off"));
    assert_int_equal(load_changed_calibration("fy_px = 2400", "fy_px = 9000"), -EINVAL);
    assert_non_null(strstr(err, "[camera] fx_px = 2400.0, fy_px = 9000.0: no lens"));
    assert_int_equal(
        load_changed_calibration("height = 960\n", "height = 960\ndistortion = 100, 0, 0, 0, 0\n"),
        -EINVAL);
    assert_non_null(strstr(err, "[camera] distortion: k1 100"));
    assert_int_equal(
        load_changed_calibration("height = 960\n", "height = 960\ndistortion = -100, 0, 0, 0, 0\n"),
        -EINVAL);
    assert_non_null(strstr(err, "[camera] distortion: k1 -100"));
    /* a real lens's distortion loads (a wide-angle k1 and k2, a little tangential) */
    assert_int_equal(load_changed_calibration("height = 960\n",
                                              "height = 960\ndistortion = "
                                              "-0.28, 0.09, 0.001, -0.0005, -0.01\n"),
                     0);
    /* a projector's lens shift puts its principal point at the image's edge or beyond */
    assert_int_equal(load_changed_calibration("cy_px = 383.5", "cy_px = 800"), 0);
    assert_int_equal(load_changed_calibration("cy_px = 383.5", "cy_px = 99999"), -EINVAL);
    assert_non_null(strstr(err, "[projector] cy_px: 99999.0 is off the 1024x768 image by more"));
}

/* A HAL=sim build refuses a real-hardware backend rather than faking it. */
static void test_backend_not_built_in(void **state)
{
    (void)state;
    const char *path = write_file(
        "v4l2.ini", "[camera]\nbackend = v4l2\nwidth = 1280\nheight = 960\nexposure_us = 10000\n"
                    "[scan]\ncalibration = ../../config/sim-calib.ini\n");
    assert_int_equal(config_load(&cfg, path, err, sizeof(err)), 0);
    struct scan_calib calib;
    assert_int_equal(calib_load(&calib, cfg.calibration_file, 0, err, sizeof(err)), 0);
    struct hal hal;
    memset(&hal, 0, sizeof(hal));
    struct board_config bc;
    config_board(&cfg, &bc);
    int rc = board_init(&hal, &bc, &calib, err, sizeof(err));
    assert_int_not_equal(rc, 0);
    assert_non_null(strstr(err, "backend = v4l2 is not built in"));
    assert_null(hal.gpio.ops); /* nothing was set up */
}

/* docs/config.md is generated from the key tables: it must be current. */
static void test_docs_cover_every_key(void **state)
{
    (void)state;
    char *generated = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&generated, &len);
    config_print_doc(mem);
    fclose(mem);
    FILE *f = fopen("docs/config.md", "r");
    assert_non_null(f);
    static char committed[65536];
    size_t n = fread(committed, 1, sizeof(committed) - 1, f);
    fclose(f);
    committed[n] = '\0';
    if (strcmp(committed, generated) != 0)
        fail_msg("docs/config.md is stale: run 'make docs'");
    free(generated);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_config_and_defaults),
        cmocka_unit_test(test_color_spelling),
        cmocka_unit_test(test_errors_name_file_line_and_key),
        cmocka_unit_test(test_gpio_lines_by_offset_or_name),
        cmocka_unit_test(test_duplicate_key),
        cmocka_unit_test(test_missing_required_key),
        cmocka_unit_test(test_width_over_limit),
        cmocka_unit_test(test_calibration_errors),
        cmocka_unit_test(test_backend_not_built_in),
        cmocka_unit_test(test_docs_cover_every_key),
        cmocka_unit_test(test_overlong_line_refused),
        cmocka_unit_test(test_file_sets_a_key),
        cmocka_unit_test(test_light_exposure_given),
        cmocka_unit_test(test_not_a_regular_file),
        cmocka_unit_test(test_empty_calibration_and_zero_baseline),
        cmocka_unit_test(test_calibration_values_within_bounds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

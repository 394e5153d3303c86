/* The scan directory: view.ini written and read back with every key checked, frames refused with
 * their own reason (libpng's for a damaged file), and `process` refusing frames that are not the
 * ones its settings need, each fault said in one error line. */
#define _XOPEN_SOURCE 700
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <limits.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "clock_posix.h"
#include "frame_writer.h"
#include "scan_dir.h"
#include "scan_job.h"
#include "storage_posix.h"
#include "test_util.h"

#define DIR "build/test_scan_dir"
#define W 1280u
#define H 960u

static struct hal hal;
static char err[1024];

static int setup(void **state)
{
    (void)state;
    mkdir("build", 0755);
    mkdir(DIR, 0755);
    hal.log = test_rig_log;
    storage_posix_init(&hal.storage);
    clock_posix_init(&hal.clock);
    return 0;
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* A view directory holding only a view.ini of @p text. */
static const char *view_with(const char *name, const char *text)
{
    static char dir[256];
    char path[SCAN_DIR_PATH_MAX];
    snprintf(dir, sizeof(dir), DIR "/%s", name);
    assert_int_equal(scan_dir_path(path, sizeof(path), dir, 0, NULL), 0);
    assert_int_equal(hal_storage_mkdir_p(&hal.storage, path), 0);
    assert_int_equal(scan_dir_path(path, sizeof(path), dir, 0, "view.ini"), 0);
    write_text(path, text);
    return dir;
}

static void expect_view_error(const char *name, const char *text, const char *expect)
{
    static struct scan_dir_view v;
    const char *dir = view_with(name, text);
    err[0] = '\0';
    assert_int_equal(scan_dir_read_view(dir, 0, &v, err, sizeof(err)), -EINVAL);
    if (strstr(err, expect) == NULL)
        fail_msg("expected '%s' in '%s'", expect, err);
    assert_false(scan_dir_view_complete(dir, 0));
}

static void test_view_ini_round_trip(void **state)
{
    (void)state;
    static struct scan_dir_view out, in;
    struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    t.cfg.scan.colour.method = COLOUR_MULTI;
    t.cfg.scan.colour.light_exposure_us = 20000;
    memset(&out, 0, sizeof(out));
    out.index = 3;
    out.angle_mdeg = -135250;
    snprintf(out.started, sizeof(out.started), "2026-12-01T10:00:00Z");
    snprintf(out.finished, sizeof(out.finished), "2026-12-01T10:00:02Z");
    out.frames = 30;
    out.capture_retries = 2;
    out.valid_points = 123456;
    out.wall_ms = 1732.5;
    out.exposure_us = 10000;
    out.gain_milli = 1500;
    scan_dir_describe_frames(&t.cfg.scan, &t.calib, &out);
    for (unsigned r = 0; r < SCAN_REASON_COUNT; r++)
        out.reason_count[r] = 1000u * r + 7u;
    assert_int_equal(out.frame_count, 22u + 1u + 1u + 4u + 1u); /* + a dark at 20000 us */
    assert_string_equal(out.frame_name[25], "light 1 alone, 20000 us, RGB");
    assert_int_equal(scan_dir_path(err, sizeof(err), DIR "/round", 3, NULL), 0);
    assert_int_equal(hal_storage_mkdir_p(&hal.storage, err), 0);
    assert_int_equal(scan_dir_write_view(&hal.storage, DIR "/round", 3, &out), 0);
    assert_int_equal(scan_dir_read_view(DIR "/round", 3, &in, err, sizeof(err)), 0);
    assert_memory_equal(&in, &out, sizeof(in)); /* every field, every frame's name */
    assert_true(scan_dir_view_complete(DIR "/round", 3));
    assert_false(scan_dir_view_complete(DIR "/round", 4));
    static struct scan_dir_view none;
    assert_int_equal(scan_dir_read_view(DIR "/round", 4, &none, err, sizeof(err)), -ENOENT);
}

/* A view taken with every frame a config can ask for (HDR at the most exposures, rows, every
 * light bracketed) says in view.ini how many it took, each pattern at each exposure, more than
 * it keeps: its scan is read back (process, resume). It was refused, naming the key, past the
 * frames a view keeps: an HDR scan at three exposures could not be processed again. */
static void test_view_ini_of_the_most_frames(void **state)
{
    (void)state;
    static struct scan_dir_view out, in;
    struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    struct scan_params *p = &t.cfg.scan;
    p->exposure_count = SCAN_MAX_EXPOSURES;
    for (uint32_t e = 0; e < SCAN_MAX_EXPOSURES; e++)
        p->exposures_us[e] = 5000u << e; /* 10000 us, the camera's, among them */
    p->decode_rows = 1;
    p->colour.method = COLOUR_FIT;
    p->colour.bracket = 2;
    struct gray_layout layout;
    scan_layout(p, &t.calib, &layout);
    memset(&out, 0, sizeof(out));
    out.frames = gray_layout_count(&layout) * SCAN_MAX_EXPOSURES +
                 scan_light_frame_count(p, &t.calib) + 1u; /* + the view's colour */
    assert_true(out.frames > SCAN_DIR_MAX_FRAMES && out.frames <= SCAN_DIR_MAX_CAPTURED);
    scan_dir_describe_frames(p, &t.calib, &out);
    assert_true(out.frame_count <= SCAN_DIR_MAX_FRAMES && out.frame_count < out.frames);
    assert_int_equal(scan_dir_path(err, sizeof(err), DIR "/most", 0, NULL), 0);
    assert_int_equal(hal_storage_mkdir_p(&hal.storage, err), 0);
    assert_int_equal(scan_dir_write_view(&hal.storage, DIR "/most", 0, &out), 0);
    assert_int_equal(scan_dir_read_view(DIR "/most", 0, &in, err, sizeof(err)), 0);
    assert_memory_equal(&in, &out, sizeof(in));
    /* more than any view can take is still refused, naming the key */
    char text[96];
    snprintf(text, sizeof(text), "[view]\nindex = 0\nangle_mdeg = 0\nframes = %u\n",
             (unsigned)SCAN_DIR_MAX_CAPTURED + 1u);
    expect_view_error("most_frames", text, "[view] frames:");
}

/* Every key is checked: nothing is guessed, and the message names file, line and key. */
static void test_view_ini_bad_values(void **state)
{
    (void)state;
#define HEAD "[view]\nindex = 0\n"
    static const struct {
        const char *name, *text, *expect;
    } cases[] = {
        {"abc", HEAD "angle_mdeg = abc\nframes = 22\n",
         "view_000/view.ini:3: [view] angle_mdeg: 'abc' is not a whole number"},
        {"empty", HEAD "angle_mdeg =\nframes = 22\n",
         "view.ini:3: [view] angle_mdeg: '' is not a whole number"},
        {"missing", HEAD "frames = 22\n", "[view] angle_mdeg: required key is missing"},
        {"fraction", HEAD "angle_mdeg = 0\nframes = 22\nvalid_points = 1.5\n",
         "view.ini:5: [view] valid_points: '1.5' is not a whole number"},
        {"negative", HEAD "angle_mdeg = 0\nframes = 22\n[pixels]\nshadow = -4\n",
         "[pixels] shadow: -4"},
        {"twice", HEAD "angle_mdeg = 0\nangle_mdeg = 5\nframes = 22\n",
         "view.ini:4: [view] angle_mdeg: set twice"},
        {"typo", HEAD "angle_mdeg = 0\nframes = 22\nangel_mdeg = 5\n",
         "view.ini:5: [view] angel_mdeg: unknown key"},
    };
#undef HEAD
    for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++)
        expect_view_error(cases[k].name, cases[k].text, cases[k].expect);
    expect_view_error("index", "[view]\nindex = 2\nangle_mdeg = 0\nframes = 22\n",
                      "[view] index: 2, but this is view 0");
}

/* Write @p bytes as frame 3 of view 0 of @p dir. */
static void write_frame_bytes(const char *dir, const void *bytes, size_t n)
{
    char path[SCAN_DIR_PATH_MAX];
    assert_int_equal(scan_dir_frame_path(path, sizeof(path), dir, 0, 3, SCAN_FRAMES_PNG, 1), 0);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(bytes, 1, n, f), n);
    fclose(f);
}

/* Write frame 3 of view 0 of @p dir as a PNG of @p format (libpng's simplified API). */
static void write_frame_png(const char *dir, uint32_t format, uint32_t w, uint32_t h)
{
    char path[SCAN_DIR_PATH_MAX];
    assert_int_equal(scan_dir_frame_path(path, sizeof(path), dir, 0, 3, SCAN_FRAMES_PNG, 1), 0);
    png_image img;
    memset(&img, 0, sizeof(img));
    img.version = PNG_IMAGE_VERSION;
    img.width = w;
    img.height = h;
    img.format = format;
    void *pixels = calloc(1, PNG_IMAGE_SIZE(img));
    assert_non_null(pixels);
    assert_true(png_image_write_to_file(&img, path, 0, pixels, 0, NULL));
    free(pixels);
}

static int read_frame3(const char *dir, uint8_t *buf, size_t cap)
{
    err[0] = '\0';
    return scan_dir_read_frame(dir, 0, 3, buf, cap, W, H, 1, err, sizeof(err));
}

/* Each kind of bad frame is refused with its own reason, naming the file. */
static void test_bad_frames_say_why(void **state)
{
    (void)state;
    static uint8_t buf[W * H * 3];
    const char *dir = view_with("frames", "");
    char path[SCAN_DIR_PATH_MAX];
    assert_int_equal(scan_dir_frame_path(path, sizeof(path), dir, 0, 3, SCAN_FRAMES_PNG, 1), 0);
    unlink(path); /* from an earlier run */
    assert_int_equal(read_frame3(dir, buf, sizeof(buf)), -ENOENT);
    assert_non_null(strstr(err, "view_000/frame_03: no such frame (.pgm.zst, .ppm.zst, .png"));

    write_frame_png(dir, PNG_FORMAT_GRAY, W, H);
    assert_int_equal(read_frame3(dir, buf, sizeof(buf)), 0);

    write_frame_png(dir, PNG_FORMAT_GRAY, 640, 480);
    assert_int_equal(read_frame3(dir, buf, sizeof(buf)), -EINVAL);
    assert_non_null(strstr(err, "frame_03.png: 640x480, but this scan's frames are 1280x960"));

    write_frame_png(dir, PNG_FORMAT_LINEAR_Y, W, H); /* 16-bit */
    assert_int_equal(read_frame3(dir, buf, sizeof(buf)), -EINVAL);
    assert_non_null(strstr(err, "frame_03.png: a 16-bit PNG; frames are 8-bit"));

    write_frame_png(dir, PNG_FORMAT_RGBA, W, H);
    assert_int_equal(read_frame3(dir, buf, sizeof(buf)), -EINVAL);
    assert_non_null(strstr(err, "frame_03.png: a PNG with an alpha channel"));

    uint8_t noise[4096];
    srand(3);
    for (size_t i = 0; i < sizeof(noise); i++)
        noise[i] = (uint8_t)rand();
    write_frame_bytes(dir, noise, sizeof(noise));
    assert_int_equal(read_frame3(dir, buf, sizeof(buf)), -EINVAL);
    assert_non_null(strstr(err, "frame_03.png: "));
    assert_null(strstr(err, "size")); /* libpng's words, not a guess about the size */
    print_message("random bytes: %s\n", err);

    /* a real frame cut short: libpng says what it found */
    write_frame_png(dir, PNG_FORMAT_GRAY, W, H);
    assert_int_equal(truncate(path, 200), 0);
    assert_int_equal(read_frame3(dir, buf, sizeof(buf)), -EINVAL);
    assert_non_null(strstr(err, "frame_03.png: "));
    print_message("truncated: %s\n", err);
}

/* Frames kept as zstd-compressed or raw PGM/PPM come back byte for byte; a grey frame reads as
 * RGB, an RGB one is not read as grey, and damage is named. */
static void test_pnm_frames_round_trip(void **state)
{
    (void)state;
    static uint8_t frame[W * H * 3], back[W * H * 3];
    const char *dir = view_with("pnm", "");
    char path[SCAN_DIR_PATH_MAX];
    for (size_t i = 0; i < sizeof(frame); i++)
        frame[i] = (uint8_t)(i * 7u + i / W);
    const enum scan_frame_format formats[] = {SCAN_FRAMES_ZSTD, SCAN_FRAMES_PNM, SCAN_FRAMES_PNG};
    for (size_t k = 0; k < 3; k++) {
        for (uint32_t f = 4; f < 6; f++) /* the pattern grey, the colour RGB */
            assert_int_equal(scan_dir_write_frame(&hal.storage, dir, 0, f, frame, W, H,
                                                  f == 4 ? 1 : 3, formats[k]),
                             0);
        memset(back, 0, sizeof(back));
        assert_int_equal(
            scan_dir_read_frame(dir, 0, 4, back, sizeof(back), W, H, 1, err, sizeof(err)), 0);
        assert_memory_equal(back, frame, (size_t)W * H);
        assert_int_equal(
            scan_dir_read_frame(dir, 0, 5, back, sizeof(back), W, H, 3, err, sizeof(err)), 0);
        assert_memory_equal(back, frame, sizeof(frame));
        for (uint32_t f = 4; f < 6; f++) {
            assert_int_equal(scan_dir_find_frame(path, sizeof(path), dir, 0, f), 0);
            unlink(path);
        }
    }
    assert_int_equal(
        scan_dir_write_frame(&hal.storage, dir, 0, 4, frame, W, H, 1, SCAN_FRAMES_ZSTD), 0);
    assert_int_equal(scan_dir_read_frame(dir, 0, 4, back, sizeof(back), W, H, 3, err, sizeof(err)),
                     0);
    assert_int_equal(back[3 * 1000 + 2], frame[1000]); /* grey to RGB: repeated */
    assert_int_equal(
        scan_dir_write_frame(&hal.storage, dir, 0, 5, frame, W, H, 3, SCAN_FRAMES_ZSTD), 0);
    assert_int_equal(scan_dir_read_frame(dir, 0, 5, back, sizeof(back), W, H, 1, err, sizeof(err)),
                     -EINVAL);
    assert_non_null(strstr(err, "frame_05.ppm.zst: an RGB frame where a grey one belongs"));
    assert_int_equal(scan_dir_find_frame(path, sizeof(path), dir, 0, 4), 0);
    struct stat sb;
    assert_int_equal(stat(path, &sb), 0);
    assert_int_equal(truncate(path, sb.st_size + 100), 0); /* zeros after the frame */
    assert_int_equal(scan_dir_read_frame(dir, 0, 4, back, sizeof(back), W, H, 1, err, sizeof(err)),
                     -EINVAL);
    assert_non_null(strstr(err, "frame_04.pgm.zst: damaged zstd data (bytes after its frame)"));
    assert_int_equal(truncate(path, sb.st_size / 2), 0); /* cut short */
    assert_int_equal(scan_dir_read_frame(dir, 0, 4, back, sizeof(back), W, H, 1, err, sizeof(err)),
                     -EINVAL);
    assert_non_null(strstr(err, "frame_04.pgm.zst: damaged zstd data"));
    print_message("truncated zstd: %s\n", err);
    unlink(path);
    assert_int_equal(scan_dir_write_frame(&hal.storage, dir, 0, 4, frame, W, H, 1, SCAN_FRAMES_PNM),
                     0);
    assert_int_equal(scan_dir_find_frame(path, sizeof(path), dir, 0, 4), 0);
    assert_int_equal(truncate(path, 5000), 0);
    assert_int_equal(scan_dir_read_frame(dir, 0, 4, back, sizeof(back), W, H, 1, err, sizeof(err)),
                     -EINVAL);
    assert_non_null(strstr(err, "frame_04.pgm: truncated"));
    unlink(path);
}

/* A scan directory of one view whose view.ini describes the frames of @p config_text, with
 * frames 00-02 written (black) and frame 03 as @p frame3 bytes. */
static void fake_scan(const char *dir, const char *config_text, const void *frame3, size_t n)
{
    static struct scan_dir_view v;
    static uint8_t black[W * H * 3];
    char path[SCAN_DIR_PATH_MAX], cfg_path[SCAN_DIR_PATH_MAX], calib[PATH_MAX];
    struct test_rig t;
    assert_int_equal(scan_dir_path(path, sizeof(path), dir, 0, NULL), 0);
    assert_int_equal(hal_storage_mkdir_p(&hal.storage, path), 0);
    snprintf(cfg_path, sizeof(cfg_path), "%s.ini", dir);
    write_text(cfg_path, config_text);
    assert_non_null(realpath("config/sim-calib.ini", calib));
    assert_int_equal(test_rig_load(&t, cfg_path), 0);
    assert_int_equal(scan_dir_keep_settings(&hal.storage, cfg_path, calib, dir, NULL), 0);
    memset(&v, 0, sizeof(v));
    scan_dir_describe_frames(&t.cfg.scan, &t.calib, &v);
    v.frames = v.frame_count;
    assert_int_equal(scan_dir_write_view(&hal.storage, dir, 0, &v), 0);
    for (uint32_t f = 0; f < 3; f++)
        assert_int_equal(
            scan_dir_write_frame(&hal.storage, dir, 0, f, black, W, H, f ? 1 : 3, SCAN_FRAMES_ZSTD),
            0);
    write_frame_bytes(dir, frame3, n);
}

static const char *config_text(const char *colour)
{
    static char text[PATH_MAX + 512];
    char calib[PATH_MAX];
    assert_non_null(realpath("config/sim-calib.ini", calib));
    snprintf(text, sizeof(text),
             "[camera]\nbackend = sim\nwidth = 1280\nheight = 960\nexposure_us = 10000\n"
             "[lights]\ncount = 4\n[scan]\nviews = 1\ncalibration = %s\n[colour]\n%s",
             calib, colour);
    return text;
}

/* process: a damaged frame is one error naming the file and what libpng found. */
static void test_process_damaged_frame_one_error(void **state)
{
    (void)state;
    const char noise[] = "\x89PNG\r\n\x1a\n but then not a PNG at all";
    fake_scan(DIR "/damaged", config_text("method = none\n"), noise, sizeof(noise));
    struct scan_job_opts opts = {.out_dir = DIR "/damaged_out", .replace = 1};
    test_log_clear();
    assert_int_equal(scan_job_process(&hal, DIR "/damaged", &opts), -EINVAL);
    assert_true(test_log_one_error("build/test_scan_dir/damaged/view_000/frame_03.png: "));
    assert_null(strstr(test_last_log, "size"));
}

/* process --config with settings whose colour frames are not the scan's: refused before any
 * frame is read, naming the key that differs from the scan's config.ini (issue 28), or, for
 * frames captured elsewhere without one, the first frame that differs (before, frame 25 was
 * taken as what the config said it was). */
static void test_process_other_frames_refused(void **state)
{
    (void)state;
    const char png_magic[] = "\x89PNG";
    fake_scan(DIR "/multi", config_text("method = multi\n"), png_magic, sizeof(png_magic));
    const char *other = DIR "/multi_longer.ini";
    write_text(other, config_text("method = multi\nlight_exposure_us = 20000\n"));
    struct scan_job_opts opts = {.out_dir = DIR "/multi_out", .config_path = other, .replace = 1};
    test_log_clear();
    assert_int_equal(scan_job_process(&hal, DIR "/multi", &opts), -EINVAL);
    assert_true(test_log_one_error("multi/config.ini was taken with [colour] light_exposure_us = "
                                   "10000, not 20000: a re-processing keeps how the views are "
                                   "taken"));
    /* the same exposure said explicitly is the same plan */
    write_text(other, config_text("method = multi\nlight_exposure_us = 10000\n"));
    test_log_clear();
    int rc = scan_job_process(&hal, DIR "/multi", &opts);
    assert_null(strstr(test_last_log, "a re-processing keeps"));
    (void)rc;
    write_text(other, config_text("method = multi\nlight_exposure_us = 20000\n"));
    unlink(DIR "/multi/config.ini");
    test_log_clear();
    assert_int_equal(scan_job_process(&hal, DIR "/multi", &opts), -EINVAL);
    assert_true(test_log_one_error(
        "build/test_scan_dir/multi/view_000/view.ini: frame_24 is 'light 0 alone, 10000 us, "
        "RGB', but these settings need 'light 0 alone, 20000 us, RGB' there"));
    /* a scan taken without colour processed for colour: the frames it never took said so (it
     * was "frame_22 is '(none)'") */
    fake_scan(DIR "/plain", config_text("method = none\n"), png_magic, sizeof(png_magic));
    write_text(other, config_text("method = multi\n"));
    opts.out_dir = DIR "/plain_out";
    test_log_clear();
    assert_int_equal(scan_job_process(&hal, DIR "/plain", &opts), -EINVAL);
    assert_true(test_log_one_error("plain/view_000/view.ini: the view took 22 frames, and these "
                                   "settings need frame_22, 'dark: projector and lights off"));
}

/* The storage thread keeps a grey frame handed to it for copying as it was when handed over,
 * although the caller reuses its buffer at once (the decoder's frames last only until the next):
 * more frames than it has copies, so that it waits for its own writes; a frame too large to copy
 * is refused, nothing queued. */
static void test_frame_writer_copies_grey_frames(void **state)
{
    (void)state;
    static uint8_t buf[W * H], back[W * H * 3];
    const char *dir = view_with("writer", "");
    const uint32_t frames = 3u * FRAME_WRITER_COPIES;
    char failed[SCAN_DIR_PATH_MAX] = "";
    assert_int_equal(frame_writer_start(&hal.storage), 0);
    for (uint32_t f = 0; f < frames; f++) {
        memset(buf, (int)(f + 1u), sizeof(buf));
        assert_int_equal(
            frame_writer_put(dir, 0, f, buf, W, H, 1, SCAN_FRAMES_PNM, 1, failed, sizeof(failed)),
            0);
        memset(buf, 0xEE, sizeof(buf)); /* the next frame comes into the same buffer */
    }
    assert_int_equal(frame_writer_put(dir, 0, frames, back, HAL_MAX_WIDTH, HAL_MAX_HEIGHT, 3,
                                      SCAN_FRAMES_PNM, 1, failed, sizeof(failed)),
                     -EINVAL);
    assert_int_equal(frame_writer_flush(failed, sizeof(failed)), 0);
    frame_writer_stop();
    for (uint32_t f = 0; f < frames; f++) {
        assert_int_equal(
            scan_dir_read_frame(dir, 0, f, back, sizeof(back), W, H, 1, err, sizeof(err)), 0);
        for (size_t i = 0; i < (size_t)W * H; i += 4099)
            assert_int_equal(back[i], f + 1u);
    }
    assert_int_equal(
        scan_dir_read_frame(dir, 0, frames, back, sizeof(back), W, H, 1, err, sizeof(err)),
        -ENOENT);
}

/* A view taken again loses its old view.ini before its first frame: were it cut short, it could
 * not pass for finished with frames of two takes. */
static void test_begin_view_removes_view_ini(void **state)
{
    (void)state;
    const char *dir = view_with("again", "[view]\nindex = 0\nangle_mdeg = 0\nframes = 22\n");
    assert_true(scan_dir_view_complete(dir, 0));
    assert_int_equal(scan_dir_begin_view(&hal.storage, dir, 0), 0);
    assert_false(scan_dir_view_complete(dir, 0));
    assert_int_equal(scan_dir_begin_view(&hal.storage, dir, 1), 0); /* new: made */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_view_ini_round_trip),
        cmocka_unit_test(test_view_ini_of_the_most_frames),
        cmocka_unit_test(test_view_ini_bad_values),
        cmocka_unit_test(test_bad_frames_say_why),
        cmocka_unit_test(test_pnm_frames_round_trip),
        cmocka_unit_test(test_process_damaged_frame_one_error),
        cmocka_unit_test(test_process_other_frames_refused),
        cmocka_unit_test(test_begin_view_removes_view_ini),
        cmocka_unit_test(test_frame_writer_copies_grey_frames),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}

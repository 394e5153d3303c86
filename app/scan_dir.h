/* The scan directory (docs/scan-format.md): its file names, view.ini and registration.ini, and its
 * frames. The one place that knows the layout: scan, process, resume and the tests use it. */
#ifndef SCAN_DIR_H
#define SCAN_DIR_H

#include "colour.h"
#include "decode.h"
#include "hal.h"
#include "reg.h"
#include "scan.h"
#include "scan_types.h"

#include <stddef.h>
#include <stdint.h>

/** Frames a view can hold: the patterns, then the colour frames. */
#define SCAN_DIR_MAX_FRAMES (DECODE_MAX_PATTERNS + COLOUR_MAX_FRAMES + 1) /* + HDR colour */
/** Frames a view can take (view.ini's frames): with HDR each pattern at every exposure. */
#define SCAN_DIR_MAX_CAPTURED                                                                      \
    (DECODE_MAX_PATTERNS * SCAN_MAX_EXPOSURES + COLOUR_MAX_FRAMES + 1) /* + HDR colour */
/** Longest description of a frame in view.ini ("light 3 alone, 20000 us, RGB"). */
#define SCAN_DIR_FRAME_NAME 64u
/* The files of a scan directory (docs/scan-format.md), named here only. At its top: */
#define SCAN_FILE_CONFIG "config.ini"           /* the settings it was taken with */
#define SCAN_FILE_CALIBRATION "calibration.ini" /* and the rig's calibration */
#define SCAN_FILE_MESH_PLY "mesh.ply"           /* the model, in four formats */
#define SCAN_FILE_MESH_OBJ "mesh.obj"
#define SCAN_FILE_MESH_STL "mesh.stl"
#define SCAN_FILE_MESH_GLB "mesh.glb"
#define SCAN_FILE_MESH_MTL "mesh.mtl"           /* mesh.obj's material: its texture */
#define SCAN_FILE_TEXTURE "texture.png"         /* the model's texture atlas (sRGB) */
#define SCAN_FILE_REFLECTANCE "reflectance.ini" /* [colour] method = fit's materials */
#define SCAN_FILE_WARNINGS "warnings.txt"       /* what the model lacks, a line each */
#define SCAN_FILE_SUMMARY "summary.ini"         /* last: the scan is complete */
#define SCAN_FILE_REPORT "report.html"
#define SCAN_FILE_LIVE "live.png" /* the camera's picture while a scan asks (a second pass) */
/* In each view's folder (view_NNN), beside its frames: */
#define SCAN_FILE_VIEW "view.ini" /* last of a view's capture: the view is complete */
#define SCAN_FILE_RANGE "range.bin"
#define SCAN_FILE_REGISTRATION "registration.ini"
#define SCAN_FILE_CLOUD "cloud.ply"
#define SCAN_FILE_TARGET "target.ini" /* calibration captures: what stood on the table */

/** Room for any path inside a scan directory. */
#define SCAN_DIR_PATH_MAX (HAL_MAX_PATH + 64u)

/** What a view's view.ini records (written last: its presence means the view is complete). */
struct scan_dir_view {
    uint32_t index;
    int32_t angle_mdeg;             /**< as the controller reported it after the move */
    char started[32], finished[32]; /**< UTC, ISO 8601 */
    uint32_t frames;                /**< frames captured, retries not counted */
    uint32_t capture_retries;
    uint32_t valid_points;
    double wall_ms;
    uint32_t exposure_us, gain_milli; /**< the camera's for the patterns */
    uint32_t frame_count;             /**< frames described in frame_name */
    char frame_name[SCAN_DIR_MAX_FRAMES][SCAN_DIR_FRAME_NAME]; /**< what each frame shows */
    uint32_t reason_count[SCAN_REASON_COUNT];                  /**< pixels per reason code */
};

/** Path of @p name in the scan directory @p dir (@p view < 0), or in view @p view's directory
 *  (@p name NULL: that directory itself). @retval 0 @retval -ENAMETOOLONG */
int scan_dir_path(char *buf, size_t len, const char *dir, int view, const char *name);

/** How frames are kept ([output] frame_format): make bench compares them. */
enum scan_frame_format {
    SCAN_FRAMES_ZSTD, /**< frame_NN.pgm.zst / .ppm.zst: a PGM/PPM in one zstd frame (zstd -d) */
    SCAN_FRAMES_PNG,  /**< frame_NN.png */
    SCAN_FRAMES_PNM,  /**< frame_NN.pgm / .ppm, uncompressed */
};

/** Path of frame @p frame of view @p view as @p format writes it (@p channels 1 or 3).
 *  @retval 0 @retval -ENAMETOOLONG */
int scan_dir_frame_path(char *buf, size_t len, const char *dir, uint32_t view, uint32_t frame,
                        enum scan_frame_format format, uint32_t channels);

/** Path of the file frame @p frame of view @p view is kept in, whatever its format.
 *  @retval 0 @retval -ENOENT none (@p buf: the frame's path without an ending)
 *  @retval -ENAMETOOLONG @retval -errno there but not to be looked at (-ELOOP a link loop,
 *  -EACCES; @p buf: that path) */
int scan_dir_find_frame(char *buf, size_t len, const char *dir, uint32_t view, uint32_t frame);

/** Describe every frame a view of @p params and @p calib takes, in order, into
 *  @p v->frame_name and @p v->frame_count. */
void scan_dir_describe_frames(const struct scan_params *params, const struct scan_calib *calib,
                              struct scan_dir_view *v);

/** Write view @p view's view.ini atomically. @retval 0 @retval -errno */
int scan_dir_write_view(const struct hal_storage *st, const char *dir, uint32_t view,
                        const struct scan_dir_view *v);

/** Read view @p view's view.ini: every key checked (a number that is not one, a key twice, an
 *  unknown key, an index that is not the view's) with file, line and key in @p err.
 *  @retval 0 @retval -ENOENT no view.ini (the view did not finish) @retval -EINVAL */
int scan_dir_read_view(const char *dir, uint32_t view, struct scan_dir_view *v, char *err,
                       size_t err_len);

/** scan_dir_read_view of the file at @p path (the fuzzer's way in). */
int scan_dir_read_view_file(const char *path, uint32_t view, struct scan_dir_view *v, char *err,
                            size_t err_len);

/** How many views the scan in @p dir takes, all passes (its config.ini's [scan] views x passes;
 *  a key not there has the config's default). Thread-safe (the web server's threads ask).
 *  @retval 0 @retval -ENOENT no config.ini: not a scan directory */
int scan_dir_view_count(const char *dir, uint32_t *views);

/** @retval 1 when view @p view finished (its view.ini is there and reads). Thread-safe. */
int scan_dir_view_complete(const char *dir, uint32_t view);

/** The first of @p views views of the scan in @p dir that did not finish: where a resume takes
 *  up again (every view from it on is taken again), @p views when all finished. */
uint32_t scan_dir_first_missing(const char *dir, uint32_t views);

/** A new scan's folder under @p parent (which exists), named by when it began, UTC
 *  (2026-12-03_080907, then -2, -3 ... in the same second), made at once so that no two scans,
 *  nor a scan and the web server, take the same. @param out  its path @param name  out: its
 *  name, within @p out @retval 0 @retval -EEXIST a hundred this second @retval -errno */
int scan_dir_make_new(const char *parent, char *out, size_t len, const char **name);

/** @retval 1 when the scan in @p dir finished: every output written (summary.ini is written
 *  last; process in place removes it first) */
int scan_dir_finished(const char *dir);

/** Keep frame @p frame of view @p view (8 bits, @p channels 1 or 3) in @p format, atomically.
 *  @retval 0 @retval -errno */
int scan_dir_write_frame(const struct hal_storage *st, const char *dir, uint32_t view,
                         uint32_t frame, const uint8_t *pixels, uint32_t width, uint32_t height,
                         uint32_t channels, enum scan_frame_format format);

/** Read frame @p frame of view @p view into @p pixels as @p channels (1 or 3), whatever format
 *  it was kept in; it must be 8 bits without alpha, @p width x @p height. @p err names the file and
 * says what is wrong (libpng's own words for a damaged file). @retval 0 @retval -ENOENT @retval
 * -EINVAL */
int scan_dir_read_frame(const char *dir, uint32_t view, uint32_t frame, uint8_t *pixels,
                        size_t capacity, uint32_t width, uint32_t height, uint32_t channels,
                        char *err, size_t err_len);

/** Keep view @p view's range image (range.bin: reason per pixel; point, normal, colour and
 *  colour confidence per valid pixel), atomically, so that the model can be made again (after
 *  the registration, by resume, by process) without decoding the frames.
 *  @retval 0 @retval -errno */
int scan_dir_write_range(const struct hal_storage *st, const char *dir, uint32_t view,
                         const struct scan_view *v);

/** Read view @p view's range.bin into @p s's buffers (scan_restore_view); @p v points at them.
 *  It must be @p width x @p height. @retval 0 @retval -ENOENT none @retval -EINVAL damaged or
 *  of another size (@p err names the file and says what) */
int scan_dir_read_range(struct scan_ctx *s, const char *dir, uint32_t view, uint32_t width,
                        uint32_t height, struct scan_view *v, char *err, size_t err_len);

/** What a view's range.bin shows, as pictures (report.html, the web page's thumbnails): its
 *  size, then, in the caller's buffers of @p capacity pixels, the reason code of every pixel and
 *  the colour of the valid ones (linear x 255, black elsewhere; @p rgb may be NULL).
 *  @retval 0 @retval -ENOENT @retval -EINVAL damaged, or larger than @p capacity */
int scan_dir_read_range_image(const char *dir, uint32_t view, uint8_t *reason, uint8_t *rgb,
                              size_t capacity, uint32_t *width, uint32_t *height);

/** Write view @p view's registration.ini: the scan's joint registration @p r, this view's part
 *  of it @p v, and @p pose, the camera-to-object pose it was fused with.
 *  @retval 0 @retval -errno */
struct reflect_model;
/** Keep the reflectance model of [colour] method = fit as reflectance.ini at the top of @p dir:
 *  per cluster its diffuse centre, specular colour x strength, roughness, samples and residual
 *  (docs/scan-format.md). @retval 0 @retval -errno */
int scan_dir_write_reflectance(const struct hal_storage *st, const char *dir,
                               const struct reflect_model *m);

int scan_dir_write_registration(const struct hal_storage *st, const char *dir, uint32_t view,
                                const struct reg_report *r, const struct reg_view *v,
                                const struct frame_xform *pose);

/** The pose view @p view was fused with, from its registration.ini (the tools that measure a
 *  scan read it back). @retval 0 @retval -ENOENT no registration.ini @retval -EINVAL no pose */
int scan_dir_read_pose(const char *dir, uint32_t view, struct frame_xform *pose);

/** How scan_dir_open treats what @p dir already holds. */
enum scan_dir_mode {
    SCAN_DIR_EXISTING, /**< a scan to finish or process in place: kept as it is */
    SCAN_DIR_NEW,      /**< a new scan or new results: the directory must be empty or absent */
    SCAN_DIR_REPLACE,  /**< the same, but a scan already there is removed first (only a scan's
                            own files: anything else there is refused, nothing removed) */
};

/** Make @p dir (and its parents) and lock it for this process, so that a second scanner cannot
 *  write into it at the same time. @param lock_fd  out: held until scan_dir_close
 *  @retval 0 @retval -EBUSY another scanner has it @retval -EEXIST not empty (NEW), or holds
 *  other files than a scan's (REPLACE) @retval -errno; @p err says which and what to do */
int scan_dir_open(const struct hal_storage *st, const char *dir, enum scan_dir_mode mode,
                  int *lock_fd, char *err, size_t err_len);
/** Release the lock of scan_dir_open (-1: none). */
void scan_dir_close(int lock_fd);

/** Before view @p view's first frame: its directory exists and holds no view.ini, so that a
 *  view cut short is never taken as finished with frames of another take. @retval 0 @retval
 *  -errno */
int scan_dir_begin_view(const struct hal_storage *st, const char *dir, uint32_t view);

/** The lines of @p dir's warnings.txt, in order, to @p each (its newline taken off; a line
 *  longer than @p line_len - 1 bytes cut there), the first @p max of them: a report and the web
 *  page read it alike. A file that is not a regular one (a pipe planted there) or a symbolic
 *  link (to /etc/passwd) is not read.
 *  @retval the lines read (0: no file) */
unsigned scan_dir_each_warning(const char *dir, unsigned max, size_t line_len,
                               void (*each)(void *priv, const char *line), void *priv);

/** Remove file @p name of @p dir (of view @p view, or -1: the scan's own) when it is there.
 *  @retval 0 removed, or there was none @retval -errno */
int scan_dir_remove(const char *dir, int view, const char *name);

/** Remove what interrupted writes (a kill, a power cut) left in the scan directory @p dir and
 *  in the directories of its views 0 .. @p views - 1. @retval 0 @retval -errno */
int scan_dir_sweep(const struct hal_storage *st, const char *dir, uint32_t views);

/** Copy a small file (config, calibration: up to 64 KiB) durably. @retval 0 @retval -errno
 *  @retval -EFBIG larger */
int scan_dir_copy_file(const struct hal_storage *st, const char *from, const char *to);

/** Keep the config and the calibration a scan ran with (config.ini, calibration.ini).
 *  @param chosen  lines config.ini gets after the config's own (what the scan chose itself:
 *  [scan] auto_exposure), or NULL @retval 0 @retval -errno @retval -EFBIG too large */
int scan_dir_keep_settings(const struct hal_storage *st, const char *config_path,
                           const char *calibration_path, const char *dir, const char *chosen);

#endif

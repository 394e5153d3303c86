/* The simulator board: every HAL device backed by the simulated rig, plus its ground truth. */
#define _POSIX_C_SOURCE 200809L
#include "board.h"

#include "board_albedo.h"
#include "gray.h"
#include "scan.h"
#include "clock_posix.h"
#include "image_io.h"
#include "sim_devices.h"
#include "pty_link.h"
#include "sim_config.h"
#include "sim_random.h"
#include "storage_posix.h"
#include "thread_posix.h"
#include "tt_server.h"
#include "turntable_modbus.h"

#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static struct {
    struct sim_rig rig;
    struct gpio_sim gpio;
    struct clock_sim clock;
    struct camera_sim camera;
    struct tt_server server; /* the simulated controller, a Modbus slave in its own thread */
    struct pty_link link;    /* RTU: the serial cable between client and controller */
    struct tt_client client; /* the scanner's real Modbus client */
    int server_open, link_open;
    int ready;
} sim;
static double truth_cpu_s; /* writing the ground truth: the simulator's work */

const char *board_name(void)
{
    return "sim";
}

static int32_t table_angle(void *priv)
{
    return tt_server_physical_position(priv); /* what the camera sees, not what is reported */
}

/* The controller on loopback TCP or on one end of a pty pair, and the client on the other. */
static int start_turntable(struct hal *hal, const struct board_config *cfg, char *err,
                           size_t err_len)
{
    struct tt_client_config cc = *cfg->turntable;
    int rc;
    if (strcmp(cc.transport, "tcp") == 0) {
        rc = tt_server_open_tcp(&sim.server, cc.host, (int)cc.port, clock_sim_now, &sim.clock, err,
                                err_len);
        cc.port = (uint32_t)sim.server.port;
    } else {
        rc = pty_link_open(&sim.link, err, err_len);
        if (rc != 0)
            return rc;
        sim.link_open = 1;
        char parity = cc.parity[0] == 'e' ? 'E' : cc.parity[0] == 'o' ? 'O' : 'N';
        rc = tt_server_open_rtu(&sim.server, sim.link.path[1], (int)cc.baud, parity,
                                (int)cc.unit_id, clock_sim_now, &sim.clock, err, err_len);
        snprintf(cc.device, sizeof(cc.device), "%s", sim.link.path[0]);
    }
    if (rc != 0)
        return rc;
    sim.server_open = 1;
    sim.server.ctrl.angle_error_mdeg = (int32_t)cfg->sim->table_angle_error_mdeg;
    rc = tt_server_start(&sim.server);
    if (rc == 0)
        rc = tt_client_open(&sim.client, &cc, &hal->clock, hal->log, &hal->turntable, err, err_len);
    if (rc != 0)
        return rc;
    sim.camera.table_angle = table_angle;
    sim.camera.table_priv = &sim.server;
    return 0;
}

static void stop_turntable(void)
{
    tt_client_close(&sim.client);
    if (sim.server_open)
        tt_server_close(&sim.server);
    if (sim.link_open)
        pty_link_close(&sim.link);
    sim.server_open = sim.link_open = 0;
}

int board_init(struct hal *hal, const struct board_config *cfg, const struct scan_calib *calib,
               char *err, size_t err_len)
{
    if (strcmp(cfg->camera_backend, "sim") != 0) {
        snprintf(err, err_len,
                 "%s: [camera] backend = %s is not built in: this scanner was built with HAL=sim "
                 "(rebuild with 'make HAL=linux' for real hardware)",
                 cfg->config_path, cfg->camera_backend);
        return -ENODEV;
    }
    char dir_buf[HAL_MAX_PATH];
    snprintf(dir_buf, sizeof(dir_buf), "%s", cfg->config_path);
    struct gray_layout layout;
    scan_layout(cfg->scan, calib, &layout);
    /* The simulator renders the true rig: the config's [sim] rig, or else the calibration. */
    const struct scan_calib *truth = cfg->sim->has_rig ? &cfg->sim->rig : calib;
    if (truth->cam_width != calib->cam_width || truth->cam_height != calib->cam_height ||
        truth->proj_width != calib->proj_width || truth->proj_height != calib->proj_height) {
        snprintf(err, err_len,
                 "%s: [sim] rig: a %ux%u camera and %ux%u projector, but the calibration's are "
                 "%ux%u and %ux%u (the same devices must be described)",
                 cfg->config_path, (unsigned)truth->cam_width, (unsigned)truth->cam_height,
                 (unsigned)truth->proj_width, (unsigned)truth->proj_height,
                 (unsigned)calib->cam_width, (unsigned)calib->cam_height,
                 (unsigned)calib->proj_width, (unsigned)calib->proj_height);
        return -EINVAL;
    }
    const char *dir = dirname(dir_buf);
    int rc = board_albedo_image_load(cfg->sim, dir, err, err_len);
    if (rc == 0)
        rc = sim_rig_init(&sim.rig, cfg->sim, truth, &layout, dir, err, err_len);
    if (rc != 0)
        return rc;
    gpio_sim_init(&sim.gpio, gray_layout_count(&layout), &hal->gpio);
    clock_sim_init(&sim.clock, &hal->clock);
    camera_sim_init(&sim.camera, &sim.rig, &sim.gpio, &sim.clock, calib->light_count, &hal->camera);
    sim.camera.frame_rate_hz = cfg->sim->frame_rate_hz;
    sim.camera.readout_us = cfg->sim->readout_us;
    storage_posix_init(&hal->storage);
    thread_posix_init(&hal->thread, 0); /* [scan] threads limits it */
    sim.ready = 1;
    rc = start_turntable(hal, cfg, err, err_len);
    if (rc != 0)
        board_shutdown(hal);
    return rc;
}

/* A board stood where the step asks, give or take [sim] placement_jitter_mm and _deg: the same
 * for every capture of one placement (drawn from the seed and the placement asked for), another
 * for the next placement and for another seed. */
static void jitter_placement(struct sim_target *st)
{
    const struct sim_config *c = &sim.rig.cfg;
    if (!(c->placement_jitter_mm > 0.0 || c->placement_jitter_deg > 0.0))
        return;
    uint64_t state = 0x91ac3ull ^ ((uint64_t)c->seed << 20);
    state ^= (uint64_t)llround(st->tilt_deg * 1000.0) * 0x9E3779B97F4A7C15ull;
    state ^= (uint64_t)llround(st->position_mm[1] * 1000.0) * 0xC2B2AE3D27D4EB4Full;
    for (int k = 0; k < 2; k++)
        st->position_mm[k] += (2.0 * sim_random_unit(&state) - 1.0) * c->placement_jitter_mm;
    st->tilt_deg += (2.0 * sim_random_unit(&state) - 1.0) * c->placement_jitter_deg;
}

int board_place_target(struct hal *hal, const struct board_target *t, char *err, size_t len)
{
    (void)hal;
    struct sim_target st = {
        .kind = t->kind == BOARD_TARGET_BOARD    ? SIM_TARGET_BOARD
                : t->kind == BOARD_TARGET_SPHERE ? SIM_TARGET_SPHERE
                                                 : SIM_TARGET_OBJECT,
        .sheet = t->sheet,
        .sheet_width = t->sheet_width,
        .sheet_height = t->sheet_height,
        .sheet_px_per_mm = t->sheet_px_per_mm,
        .thickness_mm = t->thickness_mm,
        .tilt_deg = t->tilt_deg,
        .diameter_mm = t->diameter_mm,
        .position_mm = {t->position_mm[0], t->position_mm[1]},
    };
    if (t->kind == BOARD_TARGET_BOARD) /* the person stands it about where asked */
        jitter_placement(&st);
    if (t->kind == BOARD_TARGET_OBJECT) { /* the person lays the object as the pass asks */
        static double first_pose[3];
        static int kept;
        if (!kept)
            memcpy(first_pose, sim.rig.cfg.object_pose_deg, sizeof(first_pose));
        kept = 1;
        memcpy(sim.rig.cfg.object_pose_deg,
               t->pass == 2 ? sim.rig.cfg.second_pass_pose_deg : first_pose, sizeof(first_pose));
    }
    return sim_rig_set_target(&sim.rig, &st, err, len);
}

static int write_truth(const struct hal *hal, const char *dir)
{
    struct sim_rig *rig = &sim.rig;
    const struct sim_truth *t = &rig->truth;
    size_t n = (size_t)rig->width * rig->height;
    char path[HAL_MAX_PATH + 64];
    int rc = -ENOMEM;
    float *depth = malloc(n * sizeof(float));
    uint8_t *img8 = malloc(n * 3);
    if (depth == NULL || img8 == NULL)
        goto out_free;
    sim_rig_update(rig);
    for (size_t i = 0; i < n; i++) {
        depth[i] = t->hit[i] ? t->pos_cam[3 * i + 2] : NAN;
        for (int k = 0; k < 3; k++)
            img8[3 * i + (size_t)k] = (uint8_t)lround(255.0 * t->albedo[3 * i + (size_t)k]);
    }
    snprintf(path, sizeof(path), "%s/truth_depth_mm.pfm", dir);
    rc = image_write_pfm(&hal->storage, path, depth, rig->width, rig->height, 1);
    if (rc != 0)
        goto out_free;
    snprintf(path, sizeof(path), "%s/truth_normal_cam.pfm", dir);
    rc = image_write_pfm(&hal->storage, path, t->normal_cam, rig->width, rig->height, 3);
    if (rc != 0)
        goto out_free;
    snprintf(path, sizeof(path), "%s/truth_albedo.png", dir);
    rc = image_write_png(&hal->storage, path, img8, rig->width, rig->height, 3);
    if (rc != 0)
        goto out_free;
    for (size_t i = 0; i < n; i++)
        img8[i] = (uint8_t)(t->proj_lit[i] ? 255 : 0);
    snprintf(path, sizeof(path), "%s/truth_projector_lit.png", dir);
    rc = image_write_png(&hal->storage, path, img8, rig->width, rig->height, 1);
    if (rc != 0)
        goto out_free;
    /* where the table really stood (a table with [sim] table_angle_error_mdeg misses) */
    char text[128];
    int len = snprintf(text, sizeof(text),
                       "; the table's true angle for this view\n[truth]\n"
                       "angle_mdeg = %d\n",
                       (int)rig->truth_angle_mdeg);
    snprintf(path, sizeof(path), "%s/truth_angle.ini", dir);
    rc = hal_storage_write_file(&hal->storage, path, text, (size_t)len);
out_free:
    free(depth);
    free(img8);
    return rc;
}

/* The object as the simulator renders it, in the object frame (mm): what a scan should give. */
int board_write_scan_extras(const struct hal *hal, const char *scan_dir)
{
    const struct sim_mesh *m = &sim.rig.mesh;
    char path[HAL_MAX_PATH + 32], header[256];
    snprintf(path, sizeof(path), "%s/truth_mesh.ply", scan_dir);
    int hl = snprintf(header, sizeof(header),
                      "ply\nformat binary_little_endian 1.0\ncomment simulator ground truth, "
                      "object frame, mm\nelement vertex %u\nproperty float x\nproperty float y\n"
                      "property float z\nelement face %u\nproperty list uchar uint "
                      "vertex_indices\nend_header\n",
                      (unsigned)m->vert_count, (unsigned)m->tri_count);
    size_t len = (size_t)hl + (size_t)m->vert_count * 12 + (size_t)m->tri_count * 13;
    uint8_t *buf = malloc(len), *q;
    if (buf == NULL)
        return -ENOMEM;
    memcpy(buf, header, (size_t)hl);
    q = buf + hl;
    memcpy(q, m->pos, (size_t)m->vert_count * 12); /* little-endian host, as the header says */
    q += (size_t)m->vert_count * 12;
    for (uint32_t t = 0; t < m->tri_count; t++, q += 13) {
        q[0] = 3;
        memcpy(q + 1, &m->tri[3 * t], 12);
    }
    int rc = hal_storage_write_file(&hal->storage, path, buf, len);
    free(buf);
    return rc;
}

int board_write_view_extras(const struct hal *hal, const char *view_dir)
{
    double t0 = clock_posix_thread_cpu_s();
    int rc = write_truth(hal, view_dir);
    truth_cpu_s += clock_posix_thread_cpu_s() - t0;
    return rc;
}

double board_simulator_cpu_s(void)
{
    return sim.camera.render_cpu_s + truth_cpu_s;
}

void board_shutdown(struct hal *hal)
{
    hal_safe_state(hal);
    stop_turntable();
    hal->turntable.ops = NULL;
    if (sim.ready)
        sim_rig_free(&sim.rig);
    sim.ready = 0;
}

/* The simulated rig has its devices only all together: bring it up, try each, take it down. */
int board_selftest(struct hal *hal, const struct board_config *cfg, const struct scan_calib *calib,
                   board_selftest_row row, void *ctx)
{
    char detail[512];
    struct hal_turntable_status st;
    uint32_t w, h;
    int rc = board_init(hal, cfg, calib, detail, sizeof(detail));
    if (rc != 0) {
        row(ctx, "simulated rig", cfg->config_path, rc, detail);
        return rc;
    }
    int cam_rc = board_grab_frame(hal, cfg->camera, &w, &h);
    snprintf(detail, sizeof(detail), "simulated frame %ux%u", (unsigned)w, (unsigned)h);
    row(ctx, "camera", "sim", cam_rc, cam_rc == 0 ? detail : strerror(-cam_rc));
    row(ctx, "gpio", "sim", 0, "simulated lines");
    int table_rc = hal_table_get_status(&hal->turntable, &st);
    snprintf(detail, sizeof(detail), "simulated controller on Modbus %s answers: at %.3f deg",
             cfg->turntable->transport, st.position_mdeg / 1000.0);
    row(ctx, "turntable", cfg->turntable->transport, table_rc,
        table_rc == 0 ? detail : strerror(-table_rc));
    board_shutdown(hal);
    return cam_rc != 0 || table_rc != 0 ? -ENODEV : 0;
}

/* ---- test-side control (sim_ctl.h) ---- */

int sim_ctl_line(enum hal_gpio_line line)
{
    return (unsigned)line < HAL_GPIO_LINE_COUNT ? sim.gpio.line[line] : -1;
}

uint32_t sim_ctl_pattern_index(void)
{
    return sim.gpio.pattern_index;
}

void sim_ctl_inject_camera_fault(enum sim_cam_fault kind, uint64_t first_frame, uint32_t count)
{
    sim.camera.fault = kind;
    sim.camera.fault_first = first_frame;
    sim.camera.fault_count = count;
}

uint64_t sim_ctl_frames(void)
{
    return sim.camera.frames;
}

uint64_t sim_ctl_time_us(void)
{
    return clock_sim_now(&sim.clock);
}

void sim_ctl_advance_us(uint64_t us)
{
    atomic_fetch_add(&sim.clock.now_us, us);
}

struct tt_server *sim_ctl_turntable(void)
{
    return &sim.server;
}

struct pty_link *sim_ctl_serial_link(void)
{
    return &sim.link;
}

struct tt_client *sim_ctl_turntable_client(void)
{
    return &sim.client;
}

struct sim_rig *sim_ctl_rig(void)
{
    return &sim.rig;
}

/* The simulator's device backends behind the HAL interfaces. */
#ifndef SIM_DEVICES_H
#define SIM_DEVICES_H

#include "hal.h"

#include <stdatomic.h>
#include "sim_ctl.h"
#include "sim_rig.h"

struct gpio_sim {
    int line[HAL_GPIO_LINE_COUNT];
    uint32_t pattern_index;
    uint32_t pattern_count;
};

struct clock_sim {
    _Atomic uint64_t now_us; /* read by the turntable controller's thread */
};

struct camera_sim {
    struct sim_rig *rig;
    const struct gpio_sim *gpio;
    struct clock_sim *clock; /* frames are paced as a streaming sensor paces them */
    uint32_t light_count;
    double frame_rate_hz; /* the sensor streams at this rate; 0: a frame takes its exposure */
    uint32_t readout_us;  /* from a frame's end to its arrival (ISP, transfer) */
    double render_cpu_s;  /* CPU time spent rendering: the simulator's, not the firmware's */
    struct hal_camera_config cfg;
    int32_t (*table_angle)(void *priv); /* where the turntable is, if there is one */
    void *table_priv;
    int is_open;
    uint64_t frames;   /* captures attempted since open */
    uint64_t last_key; /* what the last frame showed, and how many in a row did (noise_id) */
    uint32_t repeat;
    struct sim_sources shown; /* what the last frame showed, when and at what table angle: */
    uint64_t shown_start_us;  /* what a stale frame shows again */
    int32_t shown_angle_mdeg;
    int has_shown;
    enum sim_cam_fault fault;
    uint64_t fault_first;
    uint32_t fault_count;
};

void gpio_sim_init(struct gpio_sim *g, uint32_t pattern_count, struct hal_gpio *out);
void gpio_sim_sources(const struct gpio_sim *g, uint32_t light_count, struct sim_sources *src);
void clock_sim_init(struct clock_sim *c, struct hal_clock *out);
/** Virtual time now, for other threads of the simulator. */
uint64_t clock_sim_now(void *clock_sim);
void camera_sim_init(struct camera_sim *cam, struct sim_rig *rig, const struct gpio_sim *gpio,
                     struct clock_sim *clock, uint32_t light_count, struct hal_camera *out);

#endif

/* Simulated GPIO: the lines drive the virtual projector (enable, trigger, reset) and the lights. */
#include "sim_devices.h"

#include <errno.h>
#include <string.h>

static int gpio_sim_set(void *priv, enum hal_gpio_line line, int value)
{
    struct gpio_sim *g = priv;
    if ((unsigned)line >= HAL_GPIO_LINE_COUNT)
        return -EINVAL;
    int rising = value && !g->line[line];
    g->line[line] = value ? 1 : 0;
    /* A DLP projector in pattern-sequence mode: trigger edges step, reset returns to 0. */
    if (rising && line == HAL_GPIO_PROJECTOR_TRIGGER)
        g->pattern_index = (g->pattern_index + 1u) % g->pattern_count;
    if (rising && line == HAL_GPIO_PROJECTOR_RESET)
        g->pattern_index = 0;
    return 0;
}

static int gpio_sim_get(void *priv, enum hal_gpio_line line, int *value)
{
    struct gpio_sim *g = priv;
    if ((unsigned)line >= HAL_GPIO_LINE_COUNT)
        return -EINVAL;
    *value = g->line[line];
    return 0;
}

static int gpio_sim_safe_state(void *priv)
{
    struct gpio_sim *g = priv;
    memset(g->line, 0, sizeof(g->line));
    return 0;
}

static const struct hal_gpio_ops gpio_sim_ops = {
    .set = gpio_sim_set,
    .get = gpio_sim_get,
    .safe_state = gpio_sim_safe_state,
};

void gpio_sim_init(struct gpio_sim *g, uint32_t pattern_count, struct hal_gpio *out)
{
    memset(g, 0, sizeof(*g));
    g->pattern_count = pattern_count;
    out->ops = &gpio_sim_ops;
    out->priv = g;
}

/* Projector and light state as the camera will see it. */
void gpio_sim_sources(const struct gpio_sim *g, uint32_t light_count, struct sim_sources *src)
{
    src->projector_on = g->line[HAL_GPIO_PROJECTOR_ENABLE];
    src->pattern_index = g->pattern_index;
    src->lights_mask = 0;
    for (uint32_t i = 0; i < light_count; i++)
        if (g->line[HAL_GPIO_LIGHT_0 + i])
            src->lights_mask |= 1u << i;
}

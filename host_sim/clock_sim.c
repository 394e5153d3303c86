/* Virtual clock: time moves only when the firmware sleeps, so simulated runs are repeatable. */
#include "sim_devices.h"

uint64_t clock_sim_now(void *priv)
{
    return atomic_load(&((struct clock_sim *)priv)->now_us);
}

static int clock_sim_now_op(void *priv, uint64_t *now_us)
{
    *now_us = clock_sim_now(priv);
    return 0;
}

static int clock_sim_sleep(void *priv, uint64_t us)
{
    atomic_fetch_add(&((struct clock_sim *)priv)->now_us, us);
    return 0;
}

static int clock_sim_safe_state(void *priv)
{
    (void)priv;
    return 0;
}

static const struct hal_clock_ops clock_sim_ops = {
    .now_us = clock_sim_now_op,
    .sleep_us = clock_sim_sleep,
    .safe_state = clock_sim_safe_state,
};

void clock_sim_init(struct clock_sim *c, struct hal_clock *out)
{
    atomic_store(&c->now_us, 0);
    out->ops = &clock_sim_ops;
    out->priv = c;
}

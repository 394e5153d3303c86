/* Deterministic random numbers for the simulator and its measurements (SplitMix64). */
#ifndef SIM_RANDOM_H
#define SIM_RANDOM_H

#include <stdint.h>

/** Next 64 random bits of the sequence in @p state (Steele, Lea and Flood 2014). */
static inline uint64_t sim_random_next(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/** Uniform in [0, 1). */
static inline double sim_random_unit(uint64_t *state)
{
    return (double)(sim_random_next(state) >> 11) / 9007199254740992.0;
}

#endif

/* tests/mix.h - a 64-bit hash mixer (splitmix64's finaliser) for the
 * pseudo-random maps of the tests: the same input always gives the same map. */
#ifndef CM_TESTS_MIX_H
#define CM_TESTS_MIX_H

#include <stdint.h>

static inline uint64_t mix(uint64_t h)
{
    h ^= h >> 31;
    h *= UINT64_C(0x9e3779b97f4a7c15);
    h ^= h >> 29;
    h *= UINT64_C(0xbf58476d1ce4e5b9);
    return h ^ (h >> 32);
}

#endif

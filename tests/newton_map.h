/* tests/newton_map.h - Newton's method for z^3 - 1 as the shipped plugin
 * (examples/plugin/newton.c) has it, for the tests and benchmarks that
 * build it in-process: its source is included, so that what they check is
 * the plugin's map (newton_step; its cellmap_plugin() comes along unused). */
#ifndef CM_TESTS_NEWTON_MAP_H
#define CM_TESTS_NEWTON_MAP_H

#include "examples/plugin/newton.c"

#endif

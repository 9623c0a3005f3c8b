/* lib/figure_args.h - the figure options that take a value, parsed from
 * their text (the command line's and explore's --layers, --png-mode,
 * --min-basin, --aspect, --title, --labels, --palette, --view, --font-size,
 * --dpi) into lib/figure.h's png_opts, with the problem said in terms of
 * the option. */
#ifndef CM_LIB_FIGURE_ARGS_H
#define CM_LIB_FIGURE_ARGS_H

#include <stdbool.h>
#include <stddef.h>

#include "lib/figure.h"

/* The options png_opts_value takes, NULL-terminated. */
extern const char *const png_value_options[];

/* Option `name` (one of png_value_options) with its value into po; false
 * with the problem in msg ("--dpi: ..."). The strings po keeps (--title)
 * must outlive it. */
bool png_opts_value(png_opts *po, const char *name, const char *value, char *msg,
                    size_t msg_size);

#endif

/* src/serve_page.h - the HTML page of `cellmap serve` (src/serve_page.c). */
#ifndef CM_SRC_SERVE_PAGE_H
#define CM_SRC_SERVE_PAGE_H

extern const char serve_page[];

#endif

/* lib/serve.h - the basin atlas (lib/atlas.h) over HTTP, on libmicrohttpd:
 * what `cellmap serve` runs (docs/serve.md). Built into its own library
 * (cellmap_serve), so that only the programs that serve link the HTTP
 * library and its TLS stack.
 *
 * Requests: / (the page, lib/serve_page.h), /info, /tiles/Z/X/Y.png,
 * /cell?x=&y=[&zoom=][&steps=], /figure.png|svg?x0=&x1=&y0=&y1=[&w=&h=],
 * /leaflet/... (Leaflet's files by name, from CELLMAP_LEAFLET_DIR).
 * Everything else is a 404; bad parameters a 400 with the reason; methods
 * but GET and HEAD a 405; no request body is read.
 *
 * One thread (the server's) answers the requests one after another, so
 * the atlas and its session are used by one thread at a time: between
 * serve_start and serve_stop the caller must not touch them. */
#ifndef CM_LIB_SERVE_H
#define CM_LIB_SERVE_H

#include <stdbool.h>

#include "lib/atlas.h"

typedef struct server server;

/* Whether bind is an IPv4 or IPv6 address to listen on, and whether it
 * is this machine's only (127.x.x.x, ::1). */
bool serve_address_valid(const char *bind);
bool serve_is_loopback(const char *bind);

/* Serves a (borrowed until serve_stop) on bind:port (0: any free port)
 * from a thread of its own; *bound the port. CM_EINVAL for a bad address,
 * CM_EIO when it cannot listen. */
cm_status serve_start(atlas *a, const char *bind, int port, server **out, int *bound,
                      char *msg, size_t msg_size);

/* Stops serving after the request being answered (NULL: nothing). */
void serve_stop(server *s);

#endif

#!/usr/bin/env bash
# cellmap for figures_test: runs the command, and first, for a command that
# writes a PNG, the same command with OSMesa hidden (CELLMAP_OSMESA naming
# no file) so that EGL draws it, its PNG kept in $FIGURES_EGL_DIR. Not the
# long computations behind the charts (lyapunov grids, bifurcation sweeps,
# exponents: 33 of the figures' 87 s here), whose figures are drawn by the
# same chart code the other commands' EGL runs draw, nor a command that
# writes a database (it would find it made).
# usage: FIGURES_CM=PATH/TO/cellmap FIGURES_EGL_DIR=DIR figures_egl_twice.sh ARGS...
set -u
png=""
egl=1
prev=""
for a in "$@"; do
  case "$a" in
    --png=*) png=${a#--png=} ;;
    --db | --db=* | --grid | --grid=*) egl=0 ;;
  esac
  [ "$prev" = "--png" ] && png=$a
  prev=$a
done
case "${1:-}" in bifurcation | exponents) egl=0 ;; esac
if [ -n "$png" ] && [ $egl -eq 1 ]; then
  CELLMAP_OSMESA=/nonexistent/libOSMesa.so.8 "$FIGURES_CM" "$@" || exit
  mv "$png" "$FIGURES_EGL_DIR/$(basename "$png")" || exit
fi
exec "$FIGURES_CM" "$@"

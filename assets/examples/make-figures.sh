#!/usr/bin/env bash
# Makes the thesis' figures in this directory (or in OUT_DIR) with cellmap:
#   assets/examples/make-figures.sh build/cellmap [OUT_DIR]
# Each image is a basin figure with every layer: basins, attractors (black),
# switching lines (white), fixed points (white discs regular, rings virtual),
# manifolds (dashed), axes, legend and title.
set -euo pipefail
CM=$(realpath "$1")
src=$(cd "$(dirname "$0")/../.." && pwd) # before the cd below: $0 may be relative
OUT=${2:-$(cd "$(dirname "$0")" && pwd)}
cd "$OUT"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pd=microchaos-pd

# The README's quick start: the default solve's figure, by attractors. The thesis'
# figures below are drawn by cell groups (--by groups), as the thesis draws them.
"$CM" solve --png quick-start.png > /dev/null

# Fig. 4.13: alpha = 0.8, beta = 0.3, P = 0.9, D = 0.4; x_0*..x_2* regular,
# x_3* virtual, switching lines SW_1..SW_5
"$CM" solve --by groups --model $pd --param alpha=0.8,beta=0.3,P=0.9,D=0.4 --region=-1:6.5,-2.5:2.5 \
  --cells 750x500 --png fig-4.13.png --layers all --size 1200x800 > /dev/null

# Fig. 4.21: twelve tiny attractors at the switching lines (real device),
# each basin in its colour (the thesis' coloured domains), the cells that
# leave the box grey. v changes by less than 1.5 per step, so the cells are
# 0.375 tall in v: on 3-unit rows cell mapping cannot follow v's decay and
# sends 80 % of the box outside (docs/engine.md, "Slow directions"). The
# 480 cell groups are fragments of the twelve attractors' basins: by true
# orbits they join their attractor (the default --by attractors)
"$CM" solve --model $pd --param alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3 \
  --region=-125000:125000,-600:600 --cells 4000x3200 --max-steps 100000 \
  --png fig-4.21-figure.png --layers basin,attractors,overlays,axes,legend,title \
  --size 1400x600 > /dev/null

# Figs. 4.26-4.28 (thesis 4.6.3): the two regions solved apart, after Stage 1
# of their join, and the cluster that joins them (alpha = 0.078, beta = 0, P = 0.007, D = 0.02)
ex="--model $pd --param alpha=0.078,beta=0,P=0.007,D=0.02"
"$CM" solve --by groups $ex --region 0:500,-40:40 --cells 1000x1000 --png fig-4.26-left.png \
  --layers all --size 700x700 > /dev/null
"$CM" solve --by groups $ex --region 500:1000,-40:40 --cells 1000x1000 --png fig-4.26-right.png \
  --layers all --size 700x700 > /dev/null
"$CM" solve --by groups $ex --region 0:1000,-40:40 --cells 2000x1000 --split 2x1 --db "$tmp/c.cmdb" \
  > /dev/null
"$CM" render --by groups "$tmp/c.cmdb" --png fig-4.28.png --layers all --size 1400x700
# Fig. 4.27: the same two regions after Stage 1 of the join only
"$CM" solve --by groups $ex --region 0:1000,-40:40 --cells 2000x1000 --split 2x1 --stage1 \
  --png fig-4.27.png --layers all --size 1400x700 > /dev/null

# Fig. 4.30: the hybrid map with dry friction at mu = 0 and 0.095 (the thesis'
# two panels) and 0.105, where the outermost attractors are absorbed with the
# printed parameters; sticking zones and their basins grey (one legend line),
# each attractor's basin in its colour, as Fig. 4.21. v changes by less than
# 1.5 per step: cells 0.375 tall in v (3 units tall, cell mapping sent 59 %
# of the box outside), a row of them on v = 0 for the rest states
for mu in 0 0.095 0.105; do
  "$CM" solve --model microchaos-pd-friction --param mu=$mu --region=-100000:100000,-301.5:301.5 \
    --cells 3200x1609 --max-steps 100000 --png fig-4.30-mu$mu.png \
    --layers basin,attractors,overlays,axes,legend,title --size 1000x500 > /dev/null
done

# Fig. 4.2: the 1-D micro-chaos map, its graph, cobwebs and basin strip, out
# to x_8* = 8.96 (regular) and x_9* = 10.08 (virtual: beyond 10)
"$CM" solve --by groups --model microchaos-1d --param a=3.5,b=2.8 --region=-11:11 --cells 2200 \
  --png fig-4.2.png --layers all --size 800x800 > /dev/null

# Ch. 2: the dry friction oscillator's Poincare map at S = 0.32, S0 = 0.4,
# Omega = 0.5: the mirror pair of one-stick asymmetric solutions 1a and
# their basins, at the section phi = 0 and at phi = pi. The mirror symmetry
# maps one onto the other by (x, v) -> (-x, -v); the lattice is symmetric
# about the origin (cell 0 centred on it).
fo="--model friction-oscillator --region=-3.00375:3.00375,-3.00375:3.00375 --cells 801x801"
fo="$fo --max-steps 200"
"$CM" solve --by groups $fo --param S=0.32,S0=0.4,Omega=0.5,phi=0 --png fig-2-1a-phi0.png --layers all \
  --size 800x700 > /dev/null
"$CM" solve --by groups $fo --param S=0.32,S0=0.4,Omega=0.5,phi=3.141592653589793 --png fig-2-1a-phipi.png \
  --layers all --size 800x700 > /dev/null

# Fig. 2.20 (right): largest Lyapunov exponent over Omega and S at S0 = 0.4,
# with the bifurcation curves of two continuations: in Omega at S = 0.32
# (SN_1a, CS_a, CS_s) and in S at Omega = 0.5 (PD_1a, T, SS_a, the fold N)
"$CM" continue --param S=0.32,S0=0.4,Omega=0.5 --vary Omega=0.2:0.7 --both --start 0.5 \
  --start 0.58 --start 0.47 --curve S=0.005:0.4 --curves "$tmp/curves-omega.csv" --quiet
"$CM" continue --param S=0.3,S0=0.4,Omega=0.5 --vary S=0.005:0.4 --both --start 0.3 \
  --start 0.38 --start 0.04 --switch --curve Omega=0.2:0.7 --curves "$tmp/curves-s.csv" --quiet
"$CM" lyapunov --param S0=0.4 --grid Omega=0.2:0.7:60,S=0.005:0.4:48 --periods 600 \
  --curves "$tmp/curves-omega.csv" --curves "$tmp/curves-s.csv" --png fig-2.20-lyapunov.png \
  --size 900x700 > /dev/null
# Fig. 2.20 (left, S0 = 0.3) and Fig. 2.21 (S0 = 0.5, 0.8): the same curves
# from continuations where these S0 admit them (S <= S0: at S0 = 0.3 from
# the solutions at S = 0.22 that Fig. 2.19 follows, but for the period-5
# one near Omega = 0.45, whose curves take minutes; without the doubled
# branches' curves, which take seconds each), over coarser heat maps
"$CM" continue --param S=0.22,S0=0.3,Omega=0.5 --vary Omega=0.2:0.7 --both --start 0.35 \
  --start 0.4 --start 0.5 --start 0.6 --curve S=0.005:0.3 \
  --curves "$tmp/curves-omega-0.3.csv" --quiet
"$CM" continue --param S=0.22,S0=0.3,Omega=0.5 --vary S=0.005:0.3 --both --start 0.22 \
  --start 0.1 --curve Omega=0.2:0.7 --curves "$tmp/curves-s-0.3.csv" --quiet
"$CM" lyapunov --param S0=0.3 --grid Omega=0.2:0.7:40,S=0.005:0.3:32 --periods 300 \
  --curves "$tmp/curves-omega-0.3.csv" --curves "$tmp/curves-s-0.3.csv" \
  --png fig-2.20-left-lyapunov.png --size 900x700 > /dev/null
for s0 in 0.5 0.8; do
  "$CM" continue --param S=0.32,S0=$s0,Omega=0.5 --vary Omega=0.2:0.7 --both --start 0.5 \
    --start 0.58 --start 0.47 --curve S=0.005:0.5 --curves "$tmp/curves-omega-$s0.csv" --quiet
  "$CM" continue --param S=0.3,S0=$s0,Omega=0.5 --vary S=0.005:0.5 --both --start 0.3 \
    --start 0.38 --curve Omega=0.2:0.7 --curves "$tmp/curves-s-$s0.csv" --quiet
  "$CM" lyapunov --param S0=$s0 --grid Omega=0.2:0.7:40,S=0.005:0.5:32 --periods 300 \
    --curves "$tmp/curves-omega-$s0.csv" --curves "$tmp/curves-s-$s0.csv" \
    --png fig-2.21-S0-$s0-lyapunov.png --size 900x700 > /dev/null
done

# Figs. 2.3 (upper panel) and 2.16: trajectories over the sticking region
# |x - cos(Omega t)| < S0; slips red, sticks green. 2.16 starts from rest
# at S = S0 = 0.4 and settles on the symmetric two-stick solution 2s.
"$CM" simulate --param S=0.15,S0=0.15,Omega=0.45 --periods 4 --png fig-2.3-simulate.png \
  --size 900x900 > /dev/null
"$CM" simulate --param S=0.4,S0=0.4,Omega=0.5 --periods 12 --png fig-2.16-simulate.png \
  --size 900x900 > /dev/null
# Fig. 2.9: from the thesis' start (1 + 0.9 S0, 0) at S = S0 = 0.3, Omega =
# 0.5, the extremal asymmetric solution: x_max = 1 + S, one short stick a
# period (the last 4 of 400 periods)
"$CM" simulate --param S=0.3,S0=0.3,Omega=0.5 --from 1.27,0 --periods 400 --skip 396 \
  --png fig-2.9-simulate.png --size 900x900 > /dev/null
# Fig. 2.25: at S = 0.0465, S0 = 0.4, Omega = 0.5 the orbit from (1.36, 0)
# wanders chaotically for 135 periods (left: the first 60), then settles on
# a period-3 solution (right: periods 150-162)
"$CM" simulate --param S=0.0465,S0=0.4,Omega=0.5 --from 1.36,0 --periods 60 \
  --png fig-2.25-chaotic.png --size 900x900 > /dev/null
"$CM" simulate --param S=0.0465,S0=0.4,Omega=0.5 --from 1.36,0 --periods 162 --skip 150 \
  --png fig-2.25-period3.png --size 900x900 > /dev/null

# Fig. 2.23: the synchronisation estimate of the largest exponent at S =
# 0.05, S0 = 0.4, Omega = 0.5: x1 - x3 at the last 100 of 2000 periods
# against the coupling q; the copy falls onto the oscillator from q* =
# 0.0051, above the direct estimate 0.0045 (docs/models.md 9.8)
"$CM" lyapunov --method sync --param S=0.05,S0=0.4,Omega=0.5 --q 0:0.01:40 \
  --png fig-2.23-sync.png --quiet

# Fig. 2.26 (a): the map of every third stick at S = 0.0465 (S0 = 0.4, Omega =
# 0.5) from 200 random starts, and its chaotic transient's exponent:
# lambda_map = 0.2055 a step of three periods, lambda_flow = 0.005455 (the
# thesis' 0.2167 and 0.005748 from a seven-segment fit: 5 % above)
"$CM" lyapunov --method stickmap --param S=0.0465,S0=0.4,Omega=0.5 --png fig-2.26-stickmap.png \
  --quiet

# Fig. 2.22: Monte Carlo bifurcation diagram over S at S0 = 0.4, Omega = 0.5:
# 10 random starts per value, 1000 periods of transients, 50 recorded
"$CM" bifurcation --param S0=0.4,Omega=0.5 --sweep S=0.02:0.4:190 --png fig-2.22-bifurcation.png \
  > /dev/null

# Figs. 2.17-2.19 and 2.22 (bottom) by continuation: branches of periodic
# solutions with their bifurcations located and labelled, from the solutions
# that simulations settle on at the --start values. 2.17: S varied at
# Omega = 0.5, S0 = 0.4, from 1a (S = 0.3), 2s (0.38) and 1a,9seg (0.04),
# with the period-doubled 2a switched onto at PD_1a, and the thesis' point N
# (S = 0.035620, where its continuation diverged) named: it is the fold
# SN_1a at S = 0.0356144, which natural-parameter continuation cannot
# pass; 2.22 (bottom): the same
# branches' stop positions; 2.18: Omega varied at S = 0.32, S0 = 0.4, from
# 1a (0.5), 0s (0.58), 2s (0.47) and 2a (0.49); 2.19: the asymmetry Psi
# against Omega at S = 0.22, S0 = 0.4 (left) and 0.3 (right).
fig217="--param S=0.3,S0=0.4,Omega=0.5 --vary S=0.02:0.4 --both --start 0.3 --start 0.38
  --start 0.04 --switch --mark 0.03562=N"
# shellcheck disable=SC2086
"$CM" continue $fig217 --png fig-2.17-continue.png --quiet
# shellcheck disable=SC2086
"$CM" continue $fig217 --panels stops --size 900x450 --png fig-2.22-continue.png --quiet
"$CM" continue --param S=0.32,S0=0.4,Omega=0.5 --vary Omega=0.45:0.6 --both --start 0.5 \
  --start 0.58 --start 0.47 --start 0.49 --png fig-2.18-continue.png --quiet
for s0 in 0.4 0.3; do
  "$CM" continue --param S=0.22,S0=$s0,Omega=0.5 --vary Omega=0.3:0.7 --both --start 0.35 \
    --start 0.4 --start 0.45 --start 0.5 --start 0.6 --panels psi --size 900x450 \
    --png fig-2.19-continue-S0-$s0.png --quiet
done

# Figs. 4.12, C.4 and 4.14: the PD map's stability domain without quantisation
# with its eigen-structure curves, the regular fixed points against P, the
# fewest against alpha; at alpha = 0.8, beta = 0.3 (with Fig. 4.13's gains)
# and at alpha = 1.8, beta = 0.3 (Fig. 4.14, left)
"$CM" stability --param alpha=0.8,beta=0.3,P=0.9,D=0.4 --png fig-4.12-stability.png --quiet
"$CM" stability --param alpha=1.8,beta=0.3,P=3.5,D=1 --P 3.3:6:540 --png fig-4.14-stability.png \
  --quiet

# Fig. 4.9: the delay map's basins at a = 1.5, b = 0.6, with its band borders,
# the lines U_m its attractor's branches lie on, and the fixed points
"$CM" solve --by groups --model microchaos-delay --param a=1.5,b=0.6 --region=0:6,0:6 --cells 600x600 \
  --png fig-4.9.png --layers all --size 800x700 > /dev/null

# Fig. 4.33 (right): twofold quantisation, the stair-shaped switching lines of
# the rho x rho input tiles over the basins (Fig. 4.13's gains, rho = 0.7)
"$CM" solve --by groups --model microchaos-pd-twofold --param alpha=0.8,beta=0.3,P=0.9,D=0.4,rho=0.7 \
  --region=-6:6,-3:3 --cells 600x300 --png fig-4.33-twofold.png --layers all --size 1000x560 \
  > /dev/null

# Figs. 4.34 and 4.35: switching line collisions at P = 2/5, D = 2/9 (the
# lines on paper, black; first-order collisions red, higher orange):
# rho = 1.0 and 1.65 (just above 1/(P + D) = 1.61), 1/P = 2.5 and 2/P = 5
for f in 4.34:1.0:12:8 4.34:1.65:12:8 4.35:2.5:25:16 4.35:5:25:16; do
  IFS=: read -r fig rho wx wv <<< "$f"
  "$CM" solve --by groups --model microchaos-pd-twofold --param alpha=0.5,beta=0.1,P=0.4,D=0.2222222222222222,rho=$rho \
    --region=-$wx:$wx,-$wv:$wv --cells 120x80 --png fig-$fig-rho$rho.png \
    --layers overlays,axes,title --size 720x480 > /dev/null
done

# Fig. 4.11: the delay map's attractor partitioned (a = 1.3, b = 0.66)
"$CM" partition --param a=1.3,b=0.66 --png fig-4.11-partition.png --quiet
# Figs. 4.8, 4.10 and C.3: the delay map's (a, b) plane: the stable domain G,
# the domains '01' and '012' of whole basic branches with their boundary
# curves, the primitive partitions' domains; Fig. 4.11's point marked
"$CM" stability --model microchaos-delay --param a=1.3,b=0.66 --png fig-4.8-4.10-C.3-domains.png \
  --quiet
# Figs. C.1 and C.2: the delay map's attractor (black, by true orbits) where a
# basic branch stretches over its end (a = 1.55, b = 0.8: g_sup^0 = 0.6975 < b)
# and where one falls into pieces (a = 1.1, b = 0.5: d^1 = 0.231 < b)
"$CM" solve --model microchaos-delay --param a=1.55,b=0.8 --region=0:3.5,0:3.5 --cells 1050x1050 \
  --png fig-C.1.png --layers all --size 800x700 > /dev/null
"$CM" solve --model microchaos-delay --param a=1.1,b=0.5 --region=0:1.5,0:1.5 --cells 900x900 \
  --png fig-C.2.png --layers all --size 800x700 > /dev/null

# Figs. 4.16 and 4.17: the horseshoes at SW_4..7 (alpha = 0.8, beta = 0.3,
# P = 0.7, D = 0.6; repellers at 4 and 7) and the entropy estimate against P
# at SW_2..5 (alpha = 0.77, beta = 0.02, D = 0.83)
"$CM" horseshoe --param alpha=0.8,beta=0.3,P=0.7,D=0.6 --m 4:7 --png fig-4.16-horseshoe.png --quiet
"$CM" horseshoe --param alpha=0.77,beta=0.02,D=0.83 --m 2:5 --sweep P=0.6:0.75:150 \
  --png fig-4.17-entropy.png --quiet
# Fig. 4.18: at SW_3 (alpha = 0.77, beta = 0.02, D = 0.83) the second
# pre-images and third images of L and R at three plateaus of Fig. 4.17;
# Fig. 4.19: where each SW_2..5 is a full binary shift over the P-D plane
for P in 0.655 0.67 0.71; do
  "$CM" horseshoe --param alpha=0.77,beta=0.02,D=0.83,P=$P --m 3:3 --images 3 --preimages 2 \
    --png fig-4.18-P$P.png --size 900x600 --quiet
done
"$CM" horseshoe --param alpha=0.77,beta=0.02,D=0.83 --m 2:5 --sweep P=0.62:0.84:440 \
  --plane D=0.5:1.2:350 --periods 1 --png fig-4.19-plane.png --quiet
# Fig. 4.20: the crisis chart at alpha = 0.8, beta = 0.3, D = 0.6
"$CM" horseshoe --param alpha=0.8,beta=0.3,D=0.6 --m 1:10 --sweep P=0.65:1.45:160 --periods 1 \
  --crisis --png fig-4.20-crisis.png --quiet

# Figs. 4.5 and 4.7: transient chaos of the 1-D friction map at b = 1.3,
# |I0| = 0.25: the escape numbers across the domain at a = 1.5, and the mean
# escape number against a, four ways
"$CM" escape --param a=1.5,b=1.3 --I0 0.25 --cells 0 --ensemble 0 --png fig-4.5-escape.png --quiet
# the map's graph there (c = 0.15) with I_rep (orange) and I0 (blue) on the diagonal
"$CM" solve --by groups --model microchaos-1d-friction --param a=1.5,b=1.3,c=0.15 --region=-1.6:1.6 \
  --cells 3200 --png fig-4.5-graph.png --layers all --size 700x700 > /dev/null
"$CM" escape --param b=1.3 --I0 0.25 --sweep a=1.2:2.25:64 --ensemble 200000 \
  --png fig-4.7-escape.png --quiet

# Figs. 2.4 and 2.7: amplitude-frequency diagrams, (2.25) against simulation
"$CM" amplitude --param S=0.5,S0=0.5 --omega 0.1:3:290 --png fig-2.4-amplitude.png --quiet
"$CM" amplitude --param S=0.05,S0=0.05 --omega 0.1:3:290 --png fig-2.7-amplitude.png --quiet
# Figs. 2.6 (left, with 2.13's simulation: S = S0 = 0.02, Omega every
# 0.0025 from 0.1, so that 0.25 and 0.5 are on the grid: the resonances
# near 1/3 and 1/5 and the asymmetric one-stick points at 0.25 and 0.5), 2.6 (right) = 2.12 (a) (S = S0 = 0.3), 2.12 (c) and (d)
# (0.7, 0.9; (b) is Fig. 2.4), and 2.14 (S = 0.2, S0 = 0.24, where the
# asymmetric solutions' domain opens up)
"$CM" amplitude --param S=0.02,S0=0.02 --omega 0.09875:1.50125:561 --png fig-2.6-2.13-amplitude.png --quiet
for s in 0.3 0.7 0.9; do
  "$CM" amplitude --param S=$s,S0=$s --omega 0.1:3:290 --png fig-2.12-S$s-amplitude.png --quiet
done
"$CM" amplitude --param S=0.2,S0=0.24 --omega 0.09875:1.50125:561 --png fig-2.14-amplitude.png --quiet
# Fig. 2.5: H(t, Omega) of (2.29) in its four regimes; Fig. 2.10: the map of a
# perturbation of the extremal asymmetric solution (S = S0 = 0.1, Omega =
# 0.5) against eps - 2 eps^2; Fig. 2.11: the convergence to the symmetric
# solution at S = S0 = 0.1, Omega = 0.98 against |lambda_max|^n
"$CM" amplitude --h 0.6,0.4,0.3,0.25 --png fig-2.5-h.png --size 900x1200 --quiet
"$CM" amplitude --param S=0.1,S0=0.1,Omega=0.5 --extremal 0.03 --png fig-2.10-extremal.png --quiet
"$CM" amplitude --param S=0.1,S0=0.1,Omega=0.98 --converge 2500 --png fig-2.11-converge.png --quiet

# The example plugins' attractors (examples/plugin/): Newton's method for
# z^3 - 1 (three roots), the Henon map (one aperiodic attractor, its
# footprint black) and the pendulum, drawn by attractors
for p in newton henon pendulum; do
  cc -shared -fPIC -I"$src" -o "$tmp/lib$p.so" "$src/examples/plugin/$p.c" -lm
done
"$CM" solve --model-lib "$tmp/libnewton.so" --model newton --cells 1000x1000 \
  --png plugin-newton.png --size 900x760 > /dev/null
"$CM" solve --model-lib "$tmp/libhenon.so" --model henon --cells 2000x600 \
  --png plugin-henon.png --size 1000x420 > /dev/null
# the forced damped pendulum, its angle periodic (-pi:pi): the rotating
# period-1 attractor's basin is the whole cylinder
"$CM" solve --model-lib "$tmp/libpendulum.so" --model pendulum --cells 400x400 \
  --png plugin-pendulum.png --size 900x700 > /dev/null

# Chapter 3: chip formation (docs/models.md 12). Fig. 3.5: the section map's
# points against xi at zeta = 21 (3 random starts a value, 40 returns after
# 100) over the equilibrium's branch and the period-1 orbits' (stable black,
# unstable red): period 2 at 3.5, chaos from 4.34 to 9.11, period 1 at 11
"$CM" equilibria --from 1,0.1,0.2,0.25 --branch xi=1:13 --csv "$tmp/eq.csv" --quiet
"$CM" periodic --param xi=3.5 --from 1.05,0.2,0.27 --settle 200 --branch xi=1:13 \
  --csv "$tmp/po.csv" --quiet
"$CM" bifurcation --model chip-4d --sweep xi=1:13:240 --runs 3 --transient 100 --record 40 \
  --of tau2 --branches "$tmp/eq.csv" --branches "$tmp/po.csv" --png fig-3.5-bifurcation.png \
  --quiet
# Fig. 3.6: at xi = 4.8 tau2's history, spectrum and return map at the section (unimodal)
"$CM" simulate --model chip-4d --param xi=4.8 --from 1,0.1,0.2,0.3 --time 600 --skip 100 \
  --dt 0.01 --of tau2 --time-unit 1.64e-4 --fmax 10000 --returns --size 900x1000 \
  --png fig-3.6-simulate.png \
  --quiet
# Fig. 3.7: the flow's Lyapunov exponents at xi = 4.8 converging (0.63, 0, -32.7, -69.3)
"$CM" exponents --param xi=4.8 --from 1,0.1,0.2,0.3 --time 300 --transient 20 \
  --png fig-3.7-exponents.png --quiet
# Figs. 3.9-3.14: the elastic workpiece (K0 = 1.64e-4 s): at f = 1 the deflection
# growing to its stationary band, then tau2 and its spectrum (12 000 Hz); f = 0.16
# (chaotic at first) and f = 0.083 (micron-scale aperiodic deflection)
wp="--model chip-workpiece --from 1,0,0,0,0,0 --time-unit 1.64e-4 --quiet"
"$CM" simulate $wp --time 2500 --dt 0.05 --of z --fmax 3000 --png fig-3.9-simulate.png
"$CM" simulate $wp --time 6000 --skip 5900 --dt 0.01 --of tau2 --fmax 20000 \
  --png fig-3.10-simulate.png
"$CM" simulate $wp --param f=0.16 --time 1000 --dt 0.05 --of tau2 --fmax 20000 \
  --png fig-3.11-simulate.png
# Fig. 3.13: at f = 0.16 the chaos is transient: after t = 3000 a quasi-periodic
# motion whose strongest line (628 Hz) lies near the workpiece's 600 Hz
"$CM" simulate $wp --param f=0.16 --time 6000 --skip 5000 --dt 0.05 --of z --fmax 3000 \
  --png fig-3.13-simulate.png
"$CM" simulate $wp --param f=0.083 --time 2000 --dt 0.05 --of z --fmax 3000 \
  --png fig-3.14-simulate.png
# Figs. 3.12, 3.15: the thesis' TISEAN analysis of tau2 alone: its maxima at f = 0.16
# while chaotic (t < 3000) embedded in 10-12 delays, its minima at f = 0.083 in 8-9;
# Kantz's divergence curves' slope over k = 1..6: 410 and 345 1/s (thesis 462, 340)
kz="--series tau2 --time 3000 --transient 0 --dt 0.005 --radius 0.02,0.05,0.1 --fit 1:6"
"$CM" exponents $wp $kz --param f=0.16 --dims 10:12 --png fig-3.12-exponents.png
"$CM" exponents $wp $kz --param f=0.083 --values min --dims 8:9 --png fig-3.15-exponents.png
# Figs. 3.17-3.18: the built-up edge (delay model chip-bue): without it (H = 0)
# the stress settles (the equilibrium is unstable later, docs/models.md 12.3),
# with it (H = 0.1) bursts at every tooth; the exponents of Farmer's map
"$CM" simulate --model chip-bue --param H=0 --time 20 --dt 0.01 --of tau --fmax 10 \
  --png fig-3.17a-simulate.png --quiet
"$CM" simulate --model chip-bue --time 140 --dt 0.01 --of tau --fmax 10 \
  --png fig-3.17b-simulate.png --quiet
"$CM" exponents --model chip-bue --time 300 --transient 20 --png fig-3.18-exponents.png --quiet
# Fig. 3.8: the (xi, zeta) plane: the largest exponent of the section map (coloured
# where chaotic; grey where the orbit from the region's centre never crosses
# T0 = 0.1, mostly the stable equilibrium) and the equilibrium's Hopf curve
"$CM" equilibria --from 1,0.1,0.2,0.25 --branch xi=0:14 --curve zeta=2:42:40 \
  --csv "$tmp/hopf.csv" --quiet
"$CM" lyapunov --model chip-4d --grid xi=0:14:28,zeta=2:42:20 --periods 200 \
  --curves "$tmp/hopf.csv" --png fig-3.8-lyapunov.png --quiet

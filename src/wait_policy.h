/* src/wait_policy.h - an explore session's OpenMP threads sleep when idle
 * rather than spin, unless the user chose how they wait.
 *
 * Why: after a parallel region, libgomp's idle threads spin (300 000
 * rounds by default) before they sleep. A session alternates short
 * parallel regions with serial work (a pan's join and commit, a render's
 * labels), and where the two CPUs share a core (this project's 2-vCPU
 * machines) the spinning thread slows that serial work: a pan of the
 * 4.6.3 example computed in 18 ms with spinning threads and in 12 ms with
 * sleeping ones, 421's in 8.5 and 3.8 ms, and a 200-pan session with
 * renders took 20.1 s against 21.6 s (docs/engine.md). Large solves keep
 * their times either way; a small figure costs about 0.3 ms more, which is
 * why only explore asks for it.
 *
 * How: the OpenMP runtime reads OMP_WAIT_POLICY once, as it is loaded,
 * before main: so the command sets it and executes itself again with the
 * same arguments, before it does anything else. */
#ifndef CM_SRC_WAIT_POLICY_H
#define CM_SRC_WAIT_POLICY_H

/* Runs the program again (/proc/self/exe, argv) with OMP_WAIT_POLICY=passive
 * unless OMP_WAIT_POLICY or GOMP_SPINCOUNT is set. Returns only when it did
 * not: either is set, or the exec failed (the command then goes on as it
 * is, its threads spinning). */
void wait_passively(char **argv);

#endif

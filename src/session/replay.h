/*
 * session/replay.h — a render's rays traced again with no shading.
 */
#ifndef RAYES_SESSION_REPLAY_H
#define RAYES_SESSION_REPLAY_H

#include "accel/accel.h"
#include "accel/record.h"

/* Traces record's rays again on threads threads (detach the record from
 * accel first), giving the wall-clock and process CPU seconds it took.
 * Returns 0, or -1 if a thread could not start (the replay then ran on
 * fewer). */
int session_replay(const Accel *accel, const AccelRecord *record, int threads, double *wall_s,
                   double *cpu_s);

#endif /* RAYES_SESSION_REPLAY_H */

/*
 * reaper.h - the thread that, once a second, expires leases that were not renewed and fails jobs
 * past their wall time (store_reap, docs/service.md §2), and counts what it did in the metrics.
 */
#ifndef PORO_REAPER_H
#define PORO_REAPER_H

#include "server.h"

struct reaper;
/* Starts the thread; NULL when it cannot be started. */
struct reaper *reaper_start(struct server *srv);
/* Stops and joins the thread; accepts NULL and clears the pointer. */
void reaper_stop(struct reaper **r);

#endif

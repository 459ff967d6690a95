// SIGINT / SIGTERM for the binaries (inbetween-server's graceful shutdown, the CLI's Ctrl-C),
// delivered through a handler and a self-pipe rather than by blocking the signals and sigwait.
//
// Blocking works only if EVERY thread blocks them, and libraries may start threads before main:
// OpenBLAS's pthread build (the system BLAS, scripts/setup) starts its worker threads when it is
// loaded. The kernel hands a process-directed signal to a thread that does not block it, so the
// CLI's SIGINT (sigwait on a helper thread) went to the BLAS thread instead: dropped when the
// shell had set it to "ignore" (a background job), or killing the process without the cancel
// path (default action). A handler runs on whichever thread receives the signal, and only writes
// the signal number to a pipe that the waiting thread reads.
#pragma once

namespace inbetween::server {

// Installs the handler for SIGINT and SIGTERM (replacing SIG_IGN or SIG_DFL). Call once, early.
// Returns false if the pipe or the handler could not be set up.
bool InstallStopSignals();

// Blocks until SIGINT or SIGTERM arrives (after InstallStopSignals) and returns its number.
int WaitForStopSignal();

}  // namespace inbetween::server

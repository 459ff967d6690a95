// SIGINT / SIGTERM for the binaries (inbetween-server's graceful shutdown, the CLI's Ctrl-C),
// delivered through a handler and a self-pipe rather than by blocking the signals and sigwait.
//
// Blocking works only if EVERY thread blocks them, and libraries may start threads before main:
// OpenBLAS's pthread build (the system BLAS, scripts/setup) starts its worker threads when it is
// loaded. The kernel hands a process-directed signal to a thread that does not block it, so with
// sigwait a SIGTERM killed the server at once (default action, no graceful shutdown) and a SIGINT
// that the shell had set to "ignore" (a background job) was dropped by the BLAS thread. A handler
// runs on whichever thread receives the signal, and only writes the signal number to a pipe.
#pragma once

namespace inbetween::server {

// Installs the handler for SIGINT and SIGTERM (replacing SIG_IGN or SIG_DFL). Call once, early.
// Returns false if the pipe or the handler could not be set up.
bool InstallStopSignals();

// Blocks until SIGINT or SIGTERM arrives (after InstallStopSignals) and returns its number.
int WaitForStopSignal();

}  // namespace inbetween::server

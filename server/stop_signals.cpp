#include "server/stop_signals.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <initializer_list>

namespace inbetween::server {
namespace {

int stop_pipe[2] = {-1, -1};

extern "C" void OnStopSignal(int signal_number) {
  const int saved = errno;  // the interrupted thread's errno
  const unsigned char byte = static_cast<unsigned char>(signal_number);
  (void)!write(stop_pipe[1], &byte, 1);  // async-signal-safe; a full pipe just drops it
  errno = saved;
}

}  // namespace

bool InstallStopSignals() {
  if (stop_pipe[0] >= 0) return true;
  if (pipe2(stop_pipe, O_CLOEXEC) != 0) return false;
  fcntl(stop_pipe[1], F_SETFL, O_NONBLOCK);
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // other threads' interrupted system calls resume
  sigset_t unblock;
  sigemptyset(&unblock);
  for (int s : {SIGINT, SIGTERM}) {
    if (sigaction(s, &action, nullptr) != 0) return false;
    sigaddset(&unblock, s);
  }
  // A parent may have blocked them; the threads started from here on inherit this mask.
  pthread_sigmask(SIG_UNBLOCK, &unblock, nullptr);
  return true;
}

int WaitForStopSignal() {
  unsigned char byte = 0;
  for (;;) {
    // A timed wait rather than a blocking read: ThreadSanitizer (scripts/sanitize tsan) runs a
    // handler only when the thread the kernel gave the signal to next enters the sanitizer's
    // runtime, and a read that never returns is not such a point (the server did not stop on
    // SIGTERM under TSan). Each wake-up costs nothing measurable.
    pollfd ready{stop_pipe[0], POLLIN, 0};
    const int n = poll(&ready, 1, /*timeout_ms=*/200);
    if (n == 0 || (n < 0 && errno == EINTR)) continue;
    const ssize_t got = read(stop_pipe[0], &byte, 1);
    if (got == 1) return byte;
    if (got < 0 && errno == EINTR) continue;
    return SIGTERM;  // the pipe broke (cannot happen while the process runs): stop anyway
  }
}

}  // namespace inbetween::server

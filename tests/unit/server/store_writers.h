// A writer for the session stores' lost-update tests: read-modify-write of a counter kept in
// display_name, with the optimistic version check, retried on ABORTED.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <utility>

#include "server/session_store.h"

namespace inbetween::server::testing {

// Adds 1 to the counter of session `id` `increments` times; a yield between the read and the
// write lets other writers in. Returns how many ABORTED answers it saw; any other error fails the
// test and ends the loop.
inline int IncrementLoop(SessionStore& store, const std::string& id, int increments) {
  int aborted = 0;
  for (int i = 0; i < increments;) {
    absl::StatusOr<SessionState> got = store.Get(id);
    if (!got.ok()) {
      ADD_FAILURE() << got.status();
      return aborted;
    }
    const uint64_t version = got->session.version();
    got->session.set_display_name(std::to_string(std::stoi(got->session.display_name()) + 1));
    std::this_thread::yield();
    absl::StatusOr<SessionState> put = store.Put(*std::move(got), version);
    if (put.ok()) {
      ++i;
    } else if (put.status().code() == absl::StatusCode::kAborted) {
      ++aborted;
    } else {
      ADD_FAILURE() << put.status();
      return aborted;
    }
  }
  return aborted;
}

}  // namespace inbetween::server::testing

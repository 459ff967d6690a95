// Bearer-token authentication (--tokens FILE): each line "TOKEN [NAME]" (blank lines and lines
// starting with '#' ignored). A caller's identity (the owner of the sessions it creates) is the
// token's name, or a fingerprint of the token when it has none, so tokens never reach the store.
#pragma once

#include <grpcpp/server_context.h>

#include <map>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace inbetween::server {

class TokenTable {
 public:
  // Reads the file. INVALID_ARGUMENT naming the flag (--tokens) and the line on a bad file.
  static absl::StatusOr<TokenTable> Load(const std::string& path);
  static absl::StatusOr<TokenTable> Parse(absl::string_view text, absl::string_view where);

  // The owner of "authorization: Bearer TOKEN"; UNAUTHENTICATED when it is missing or unknown.
  absl::StatusOr<std::string> Authenticate(const grpc::ServerContext& context) const;
  absl::StatusOr<std::string> Owner(absl::string_view authorization) const;

  size_t size() const { return owners_.size(); }

 private:
  std::map<std::string, std::string, std::less<>> owners_;  // token -> owner
};

}  // namespace inbetween::server

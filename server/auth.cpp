// TokenTable: parsing the token file and checking the authorization header.
#include "server/auth.h"

#include <cstdint>
#include <fstream>
#include <sstream>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace inbetween::server {
namespace {

// FNV-1a 64: a stable fingerprint (not a secret-keeping hash; it only names unnamed tokens).
std::string Fingerprint(absl::string_view token) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : token) {
    h ^= c;
    h *= 1099511628211ull;
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out = "token-";
  for (int i = 60; i >= 0; i -= 4) out.push_back(kHex[(h >> i) & 0xf]);
  return out;
}

}  // namespace

absl::StatusOr<TokenTable> TokenTable::Parse(absl::string_view text, absl::string_view where) {
  TokenTable table;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || line[0] == '#') continue;
    std::vector<absl::string_view> parts =
        absl::StrSplit(line, absl::ByAnyChar(" \t"), absl::SkipEmpty());
    if (parts.size() > 2) {
      return absl::InvalidArgumentError(absl::StrCat(where, " line ", line_number,
                                                     ": expected 'TOKEN [NAME]', found ",
                                                     parts.size(), " words"));
    }
    const std::string token(parts[0]);
    std::string owner = parts.size() == 2 ? std::string(parts[1]) : Fingerprint(token);
    if (!table.owners_.emplace(token, std::move(owner)).second) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, " line ", line_number, ": the token is repeated"));
    }
  }
  if (table.owners_.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(where, " has no tokens"));
  }
  return table;
}

absl::StatusOr<TokenTable> TokenTable::Load(const std::string& path) {
  std::ifstream in(path);
  if (!in) return absl::InvalidArgumentError(absl::StrCat("--tokens: cannot read '", path, "'"));
  std::stringstream text;
  text << in.rdbuf();
  return Parse(text.str(), absl::StrCat("--tokens ", path));
}

absl::StatusOr<std::string> TokenTable::Owner(absl::string_view authorization) const {
  if (authorization.empty()) {
    return absl::UnauthenticatedError(
        "missing bearer token: send metadata 'authorization: Bearer TOKEN'");
  }
  if (!absl::StartsWithIgnoreCase(authorization, "bearer ")) {
    return absl::UnauthenticatedError("the authorization metadata is not 'Bearer TOKEN'");
  }
  const absl::string_view token = absl::StripAsciiWhitespace(authorization.substr(7));
  auto it = owners_.find(token);
  if (it == owners_.end()) return absl::UnauthenticatedError("invalid bearer token");
  return it->second;
}

absl::StatusOr<std::string> TokenTable::Authenticate(const grpc::ServerContext& context) const {
  const auto& metadata = context.client_metadata();
  auto it = metadata.find("authorization");
  if (it == metadata.end()) return Owner("");
  return Owner(absl::string_view(it->second.data(), it->second.size()));
}

}  // namespace inbetween::server

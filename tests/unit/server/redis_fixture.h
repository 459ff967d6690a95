// A real redis-server for tests: started on a free loopback port (no persistence), killed when
// the object goes away. Tests skip (GTEST_SKIP) only when the redis-server binary is absent.
#pragma once

#include <fcntl.h>
#include <hiredis/hiredis.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include "server/redis_session_store.h"

namespace inbetween::server::testing {

// The redis-server binary ($REDIS_SERVER, else the usual places), "" when there is none.
inline std::string FindRedisServer() {
  if (const char* env = std::getenv("REDIS_SERVER"); env != nullptr && access(env, X_OK) == 0) {
    return env;
  }
  for (const char* path : {"/usr/bin/redis-server", "/usr/local/bin/redis-server"}) {
    if (access(path, X_OK) == 0) return path;
  }
  return "";
}

// A loopback port that was free a moment ago (the kernel's pick for port 0).
inline int FreeLoopbackPort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof(addr);
  int port = 0;
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0 &&
      getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
    port = ntohs(addr.sin_port);
  }
  close(fd);
  return port;
}

class RedisProcess {
 public:
  // Starts redis-server; url() is empty when it could not be started.
  explicit RedisProcess(const std::string& binary) {
    for (int attempt = 0; attempt < 5 && url_.empty(); ++attempt) {
      const int port = FreeLoopbackPort();
      if (port == 0) continue;
      const std::string port_text = std::to_string(port);
      pid_ = fork();
      if (pid_ == 0) {
        const int null_fd = open("/dev/null", O_WRONLY);  // keep the test output clean
        if (null_fd >= 0) dup2(null_fd, STDOUT_FILENO);
        execl(binary.c_str(), binary.c_str(), "--port", port_text.c_str(), "--bind", "127.0.0.1",
              "--save", "", "--appendonly", "no", "--loglevel", "warning", "--protected-mode",
              "yes", static_cast<char*>(nullptr));
        _exit(127);
      }
      const std::string url = "redis://127.0.0.1:" + port_text;
      // Up to ~5 s for the server to accept connections.
      for (int i = 0; i < 100; ++i) {
        if (RedisSessionStore::Open(url).ok()) {
          // Another test's redis-server may hold the port (ours then exits): only ours counts.
          if (ServerPid(port) == pid_) {
            url_ = url;
            port_ = port;
          }
          break;
        }
        int status = 0;
        if (waitpid(pid_, &status, WNOHANG) == pid_) {  // exited: port taken, try another
          pid_ = -1;
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      if (url_.empty()) Stop();
    }
  }
  ~RedisProcess() { Stop(); }
  RedisProcess(const RedisProcess&) = delete;
  RedisProcess& operator=(const RedisProcess&) = delete;

  const std::string& url() const { return url_; }
  int port() const { return port_; }

  // Closes every other client's connection (as a Redis restart or a proxy reset would).
  void KillClients() const {
    redisContext* c = redisConnect("127.0.0.1", port_);
    if (c != nullptr && c->err == 0) {
      auto* reply = static_cast<redisReply*>(redisCommand(c, "CLIENT KILL TYPE normal SKIPME yes"));
      if (reply != nullptr) freeReplyObject(reply);
    }
    if (c != nullptr) redisFree(c);
  }

  // The process id the redis-server on `port` reports (INFO server), -1 if none answers.
  static pid_t ServerPid(int port) {
    redisContext* c = redisConnect("127.0.0.1", port);
    pid_t pid = -1;
    if (c != nullptr && c->err == 0) {
      auto* reply = static_cast<redisReply*>(redisCommand(c, "INFO server"));
      if (reply != nullptr && reply->type == REDIS_REPLY_STRING) {
        const std::string info(reply->str, reply->len);
        const size_t at = info.find("process_id:");
        if (at != std::string::npos) pid = static_cast<pid_t>(std::atol(info.c_str() + at + 11));
      }
      if (reply != nullptr) freeReplyObject(reply);
    }
    if (c != nullptr) redisFree(c);
    return pid;
  }

  void Stop() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  std::string url_;
};

}  // namespace inbetween::server::testing

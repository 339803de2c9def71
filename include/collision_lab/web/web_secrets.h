// What the web node keeps across its restarts (docs/web.md, "Restarts"): the login
// cookies' secrets and the stop tokens, so that a restart logs nobody out and every
// student can still stop their runs. Files of its own in a folder (mode 0600):
//   web_cookies      the class and teacher cookie secrets, each with a fingerprint of the
//                    code it was issued for (SHA-1 of secret and code): a changed code
//                    gets a new secret, and the old cookies stop working;
//   web_stop_tokens  "<run_id> <SHA-1 of its token>" per line, appended as runs are
//                    accepted, the newest `kept` read back (and rewritten) at the start.
// Only hashes of the tokens are stored; files are replaced whole (a new file renamed over
// the old) and never opened through a symbolic link. One web node per folder: two would
// replace each other's files. Without a folder nothing is kept (secrets of this start
// only). Thread-safe.
#pragma once

#include <cstdio>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <string>

namespace collision_lab_web {

class WebSecrets {
 public:
  /// directory: where the files are (created when missing); empty: nothing kept. Files
  /// that cannot be read or written are logged through `warn` and replaced by secrets of
  /// this start.
  WebSecrets(const std::string& directory, const std::string& class_code, const std::string& teacher_code,
             std::size_t kept, const std::function<void(const std::string&)>& warn);
  ~WebSecrets();
  WebSecrets(const WebSecrets&) = delete;
  WebSecrets& operator=(const WebSecrets&) = delete;

  const std::string& classCookie() const { return class_cookie_; }
  const std::string& teacherCookie() const { return teacher_cookie_; }

  /// Remembers run_id's stop token (its hash, on disk too); the oldest beyond `kept` are forgotten.
  void rememberStopToken(const std::string& run_id, const std::string& token);
  /// Whether a stop token of run_id is remembered.
  bool hasStopToken(const std::string& run_id) const;
  /// Whether token is run_id's (compared in constant time).
  bool stopTokenMatches(const std::string& run_id, const std::string& token) const;

  /// 64 hex digits from the system's random device.
  static std::string randomToken();
  /// SHA-1 of text, 40 hex digits.
  static std::string sha1Hex(const std::string& text);

 private:
  void keepLocked(const std::string& run_id, const std::string& hash);

  std::string class_cookie_, teacher_cookie_;
  const std::size_t kept_;
  mutable std::mutex mutex_;
  std::map<std::string, std::string> token_hashes_;  ///< run_id -> SHA-1 of its token
  std::deque<std::string> order_;                    ///< run_ids of token_hashes_, oldest first
  std::FILE* tokens_file_ = nullptr;                 ///< appended to; null: nothing kept
};

/// Constant-time comparison of two secrets.
bool sameSecret(const std::string& a, const std::string& b);

}  // namespace collision_lab_web

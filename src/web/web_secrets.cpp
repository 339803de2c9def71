#include "collision_lab/web/web_secrets.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <boost/uuid/detail/sha1.hpp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <type_traits>

namespace collision_lab_web {

namespace {

namespace fs = std::filesystem;

constexpr char kCookiesFile[] = "web_cookies";
constexpr char kTokensFile[] = "web_stop_tokens";

/// Opens path to append to, created with mode 0600 (never through a symbolic link).
std::FILE* openToAppend(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd < 0) return nullptr;
  ::fchmod(fd, 0600);
  std::FILE* file = ::fdopen(fd, "a");
  if (!file) ::close(fd);
  return file;
}

/// Replaces path by `text` whole: written to a new 0600 file beside it, then renamed over
/// it, so that a crash or a full disk leaves the old file. False when it could not.
bool replaceFile(const fs::path& path, const std::string& text) {
  std::string temporary = path.string() + ".XXXXXX";
  const int fd = ::mkstemp(temporary.data());
  if (fd < 0) return false;
  std::FILE* file = ::fdopen(fd, "w");
  if (!file) {
    ::close(fd);
    ::unlink(temporary.c_str());
    return false;
  }
  const bool written = std::fwrite(text.data(), 1, text.size(), file) == text.size() && std::fflush(file) == 0 &&
                       ::fsync(fd) == 0;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed || std::rename(temporary.c_str(), path.c_str()) != 0) {
    ::unlink(temporary.c_str());
    return false;
  }
  return true;
}

/// The secret kept for `code` in lines "<role> <secret> <fingerprint>", or a new one (and
/// `changed`) when there is none, or it was issued for another code.
std::string secretFor(const std::map<std::string, std::pair<std::string, std::string>>& kept, const std::string& role,
                      const std::string& code, bool& changed) {
  const auto it = kept.find(role);
  if (it != kept.end() && it->second.first.size() == 64 &&
      sameSecret(it->second.second, WebSecrets::sha1Hex(it->second.first + code))) {
    return it->second.first;
  }
  changed = true;
  return WebSecrets::randomToken();
}

}  // namespace

bool sameSecret(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

std::string WebSecrets::randomToken() {
  std::random_device device;
  std::string out;
  const char* hex = "0123456789abcdef";
  for (int i = 0; i < 8; ++i) {
    const std::uint32_t word = device();
    for (int b = 0; b < 8; ++b) out += hex[(word >> (4 * b)) & 0xf];
  }
  return out;
}

std::string WebSecrets::sha1Hex(const std::string& text) {
  // Boost 1.74's digest: five 32-bit words (newer Boosts give 20 bytes).
  static_assert(std::is_same_v<std::remove_extent_t<boost::uuids::detail::sha1::digest_type>, unsigned int> &&
                std::extent_v<boost::uuids::detail::sha1::digest_type> == 5);
  boost::uuids::detail::sha1 sha;
  sha.process_bytes(text.data(), text.size());
  boost::uuids::detail::sha1::digest_type digest;
  sha.get_digest(digest);
  char out[41];
  for (int i = 0; i < 5; ++i) std::snprintf(out + 8 * i, 9, "%08x", static_cast<unsigned>(digest[i]));
  return std::string(out, 40);
}

WebSecrets::WebSecrets(const std::string& directory, const std::string& class_code, const std::string& teacher_code,
                       std::size_t kept, const std::function<void(const std::string&)>& warn)
    : kept_(kept) {
  if (directory.empty()) {
    class_cookie_ = randomToken();
    teacher_cookie_ = randomToken();
    return;
  }
  std::error_code ec;
  fs::create_directories(directory, ec);
  const fs::path cookies = fs::path(directory) / kCookiesFile;
  std::map<std::string, std::pair<std::string, std::string>> stored;  // role -> {secret, fingerprint}
  {
    std::ifstream in(cookies);
    std::string role, secret, fingerprint;
    while (in >> role >> secret >> fingerprint) stored[role] = {secret, fingerprint};
  }
  bool changed = false;
  class_cookie_ = secretFor(stored, "class", class_code, changed);
  teacher_cookie_ = secretFor(stored, "teacher", teacher_code, changed);
  if (changed && !replaceFile(cookies, "class " + class_cookie_ + " " + sha1Hex(class_cookie_ + class_code) + "\nteacher " +
                                           teacher_cookie_ + " " + sha1Hex(teacher_cookie_ + teacher_code) + "\n")) {
    warn("cannot write " + cookies.string() + ": logins end when this node restarts");
  }

  const fs::path tokens = fs::path(directory) / kTokensFile;
  {
    std::ifstream in(tokens);
    std::string run_id, hash;
    while (in >> run_id >> hash) keepLocked(run_id, hash);
  }
  // Rewritten with the kept ones only (bounded), then appended to.
  std::string kept_lines;
  for (const std::string& run_id : order_) kept_lines += run_id + " " + token_hashes_[run_id] + "\n";
  if (replaceFile(tokens, kept_lines)) tokens_file_ = openToAppend(tokens);
  if (!tokens_file_) warn("cannot write " + tokens.string() + ": stop tokens end when this node restarts");
}

WebSecrets::~WebSecrets() {
  if (tokens_file_) std::fclose(tokens_file_);
}

void WebSecrets::keepLocked(const std::string& run_id, const std::string& hash) {
  if (token_hashes_.insert_or_assign(run_id, hash).second) order_.push_back(run_id);
  while (order_.size() > kept_) {
    token_hashes_.erase(order_.front());
    order_.pop_front();
  }
}

void WebSecrets::rememberStopToken(const std::string& run_id, const std::string& token) {
  const std::string hash = sha1Hex(token);
  std::lock_guard<std::mutex> lock(mutex_);
  keepLocked(run_id, hash);
  if (tokens_file_ && (std::fprintf(tokens_file_, "%s %s\n", run_id.c_str(), hash.c_str()) < 0 || std::fflush(tokens_file_) != 0)) {
    std::fclose(tokens_file_);  // this start's tokens still work; the next start's do not
    tokens_file_ = nullptr;
  }
}

bool WebSecrets::hasStopToken(const std::string& run_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return token_hashes_.count(run_id) > 0;
}

bool WebSecrets::stopTokenMatches(const std::string& run_id, const std::string& token) const {
  const std::string hash = sha1Hex(token);
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = token_hashes_.find(run_id);
  return it != token_hashes_.end() && sameSecret(hash, it->second);
}

}  // namespace collision_lab_web

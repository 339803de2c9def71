#include "collision_lab/web/web_secrets.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <boost/uuid/detail/sha1.hpp>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>

namespace collision_lab_web {

namespace {

namespace fs = std::filesystem;

constexpr char kCookiesFile[] = "web_cookies";
constexpr char kTokensFile[] = "web_stop_tokens";

/// Opens path for writing, created with mode 0600 (truncated, or appended to).
std::FILE* openPrivate(const fs::path& path, bool append) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (append ? O_APPEND : O_TRUNC), 0600);
  if (fd < 0) return nullptr;
  ::fchmod(fd, 0600);
  std::FILE* file = ::fdopen(fd, append ? "a" : "w");
  if (!file) ::close(fd);
  return file;
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
  if (changed) {
    std::FILE* out = openPrivate(cookies, false);
    if (!out || std::fprintf(out, "class %s %s\nteacher %s %s\n", class_cookie_.c_str(),
                             sha1Hex(class_cookie_ + class_code).c_str(), teacher_cookie_.c_str(),
                             sha1Hex(teacher_cookie_ + teacher_code).c_str()) < 0) {
      warn("cannot write " + cookies.string() + ": logins end when this node restarts");
    }
    if (out) std::fclose(out);
  }

  const fs::path tokens = fs::path(directory) / kTokensFile;
  {
    std::ifstream in(tokens);
    std::string run_id, hash;
    while (in >> run_id >> hash) keepLocked(run_id, hash);
  }
  // Rewritten with the kept ones only (bounded), then appended to.
  std::FILE* rewritten = openPrivate(tokens, false);
  if (rewritten) {
    for (const std::string& run_id : order_) std::fprintf(rewritten, "%s %s\n", run_id.c_str(), token_hashes_[run_id].c_str());
    std::fclose(rewritten);
  }
  tokens_file_ = openPrivate(tokens, true);
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
  if (tokens_file_) {
    std::fprintf(tokens_file_, "%s %s\n", run_id.c_str(), hash.c_str());
    std::fflush(tokens_file_);
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

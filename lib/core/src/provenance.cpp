#include "articula/core/provenance.hpp"

#include <openssl/evp.h>

#include <cstdlib>
#include <fstream>
#include <memory>

#include "articula/core/error.hpp"
#include "articula/core/version.hpp"

namespace articula {

namespace {
// OpenSSL's EVP digest: a well-kept SHA-256 instead of a hand-written one.
class Sha256 {
 public:
  Sha256() : ctx_(EVP_MD_CTX_new(), EVP_MD_CTX_free) { EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr); }
  void update(const char* data, size_t n) { EVP_DigestUpdate(ctx_.get(), data, n); }
  std::string hex() {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    EVP_DigestFinal_ex(ctx_.get(), digest, &n);
    static const char* digits = "0123456789abcdef";
    std::string out;
    for (unsigned int i = 0; i < n; ++i) {
      out += digits[digest[i] >> 4];
      out += digits[digest[i] & 15];
    }
    return out;
  }

 private:
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx_;
};

std::string g_command_line, g_invoking_command;
}  // namespace

std::string sha256File(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot read '" + path.string() + "' to hash it");
  Sha256 sha;
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    sha.update(buffer.data(), static_cast<size_t>(in.gcount()));
  }
  return sha.hex();
}

std::string sha256String(const std::string& bytes) {
  Sha256 sha;
  sha.update(bytes.data(), bytes.size());
  return sha.hex();
}

void setCommandLine(int argc, const char* const* argv) {
  g_command_line.clear();
  for (int i = 0; i < argc; ++i) {
    if (i) g_command_line += ' ';
    std::string arg = argv[i];
    bool quote = arg.find_first_of(" \t'\"") != std::string::npos || arg.empty();
    g_command_line += quote ? "'" + arg + "'" : arg;
  }
}

std::string commandLine() { return g_command_line; }
void setCommandLineString(const std::string& command) { g_command_line = command; }
std::string invokingCommand() { return g_invoking_command; }
void setInvokingCommand(const std::string& command) { g_invoking_command = command; }

nlohmann::json provenanceJson(const Provenance& p) {
  nlohmann::json inputs = nlohmann::json::array();
  for (const auto& path : p.inputs) {
    // A DICOM folder is hashed file by file elsewhere; here only plain files.
    std::string hash = std::filesystem::is_regular_file(path) ? sha256File(path) : "";
    inputs.push_back({{"path", path.string()}, {"sha256", hash}});
  }
  nlohmann::json j = {{"articula_version", version()},
                      {"git_commit", gitCommit()},
                      {"command", commandLine()},
                      {"parameters", p.parameters},
                      {"inputs", inputs},
                      {"threads", p.threads},
                      {"coordinate_system", "LPS"},
                      {"units", "mm"}};
  if (p.seed >= 0) j["seed"] = p.seed;
  if (!g_invoking_command.empty()) j["invoked_by"] = g_invoking_command;
  // How the process's memory was set up (huge pages: lib/cli/src/huge_pages.hpp).
  if (const char* tunables = std::getenv("GLIBC_TUNABLES")) j["glibc_tunables"] = tunables;
  return j;
}

}  // namespace articula

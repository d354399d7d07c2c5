#include "test_support.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "nsg/core/files.h"
#include "nsg/core/sha256.h"

namespace fs = std::filesystem;

namespace nsg::test {
namespace {
std::string env_or(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return (v != nullptr && *v != '\0') ? v : fallback;
}
std::atomic<int> g_counter{0};
}  // namespace

fs::path source_dir() { return env_or("NSG_SOURCE_DIR", NSG_SOURCE_DIR_DEFAULT); }
fs::path data_dir() { return source_dir() / "tests" / "data"; }
fs::path nsgraph_exe() { return env_or("NSG_EXE", NSG_EXE_DEFAULT); }

TempDir::TempDir(const std::string& name) {
  const fs::path root = fs::path(env_or("NSG_TEST_TMP", "/tmp")) / "nsg-tests";
  path_ = root / (name + "-" + std::to_string(::getpid()) + "-" + std::to_string(g_counter++));
  fs::remove_all(path_);
  fs::create_directories(path_);
}

TempDir::~TempDir() {
  if (std::getenv("NSG_KEEP_TMP") == nullptr) {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
}

CommandResult run_program(const std::vector<std::string>& argv) {
  TempDir io("proc");
  const fs::path out_path = io / "stdout", err_path = io / "stderr";
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int in = ::open("/dev/null", O_RDONLY);
    ::dup2(out, 1);
    ::dup2(err, 2);
    ::dup2(in, 0);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  int status = 0;
  struct rusage usage {};
  ::wait4(pid, &status, 0, &usage);
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.peak_rss_bytes = static_cast<uint64_t>(usage.ru_maxrss) * 1024;  // Linux: KiB
  r.out = read_text(out_path);
  r.err = read_text(err_path);
  return r;
}

CommandResult run_nsgraph(const std::vector<std::string>& args) {
  std::vector<std::string> argv{nsgraph_exe().string()};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_program(argv);
}

void write_text(const fs::path& path, const std::string& text) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  std::ofstream f(path, std::ios::binary);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + path.string());
}

std::string read_text(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

fs::path cached_folder(const std::string& name, const std::string& key,
                       const std::function<void(const fs::path&)>& produce) {
  const fs::path root = fs::path(env_or("NSG_BINARY_DIR", NSG_BINARY_DIR_DEFAULT)) / "test-cache";
  const fs::path done = root / (name + "-" + key);
  if (fs::is_directory(done)) return done;
  // ctest starts many processes that want the same folder at once: one produces it, the
  // others wait on the lock instead of producing it again.
  fs::create_directories(root);
  const int lock = ::open((root / (name + ".lock")).c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock >= 0) ::flock(lock, LOCK_EX);
  struct Unlock {
    int fd;
    ~Unlock() {
      if (fd >= 0) ::close(fd);  // closing releases the lock
    }
  } unlock{lock};
  if (fs::is_directory(done)) return done;
  const fs::path work = root / (name + "-" + key + ".tmp-" + std::to_string(::getpid()));
  fs::remove_all(work);
  fs::create_directories(work);
  produce(work);
  std::error_code ec;
  fs::rename(work, done, ec);  // another process may have won the race: use its copy
  if (ec) {
    fs::remove_all(work);
    return done;
  }
  // Older builds' copies of the same folder are stale now.
  for (const auto& entry : fs::directory_iterator(root)) {
    const std::string other = entry.path().filename().string();
    if (entry.path() != done && other.rfind(name + "-", 0) == 0 && other.find(".tmp-") == std::string::npos)
      fs::remove_all(entry.path(), ec);
  }
  return done;
}

std::string nsgraph_build_key() {
  const fs::path exe = nsgraph_exe();
  const auto stamp = fs::last_write_time(exe).time_since_epoch().count();
  return std::to_string(fs::file_size(exe)) + "-" + std::to_string(stamp);
}

fs::path tiny_release() {
  const fs::path config = source_dir() / "samples/synth/tiny.json";
  const std::string key = nsgraph_build_key() + "-" + sha256_hex(read_file(config)).substr(0, 16);
  return cached_folder("release_tiny", key, [&](const fs::path& dir) {
    const CommandResult r = run_nsgraph(
        {"synth", "--quiet", "--config", config.string(), "--out", dir.string(), "--seed", "7", "--threads", "2"});
    if (r.exit_code != 0) throw std::runtime_error("synth tiny failed: " + r.err);
  });
}

}  // namespace nsg::test

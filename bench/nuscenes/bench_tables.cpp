// bench_nuscenes: loading a large sample_data-shaped table (docs/benchmarks.md: ≥ 0.8 GB/s, peak
// memory ≤ 2× the file). Generates the table by streaming (low memory) into
// $NSG_BENCH_DIR (default: the system temp folder), then loads it in a fresh forked child
// per repetition so VmHWM (peak RSS) measures the load alone.
//   NSG_BENCH_MB   table size in MB (default 320)
//   NSG_BENCH_REPS repetitions (default 3)
//   NSG_BENCH_KEEP keep the generated file
//   NSG_BENCH_SCALE_MB  instead: the scale case (the real trainval sample_data.json
//                  is over 1 GB): one table of this many MB (e.g. 2500), loaded once; checks
//                  the record count and peak RSS ≤ 1× the file, prints PASS or FAIL lines and
//                  exits 1 on FAIL. The table is always deleted afterwards.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "nsg/core/error.h"
#include "nsg/nuscenes/tables.h"

namespace {

namespace fs = std::filesystem;

long env_long(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return (v != nullptr && *v != '\0') ? std::strtol(v, nullptr, 10) : fallback;
}

// Peak resident set size of this process in bytes (VmHWM), 0 if unknown.
std::uint64_t peak_rss_bytes() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return 0;
  char line[256];
  std::uint64_t kb = 0;
  while (std::fgets(line, sizeof line, f) != nullptr) {
    if (std::strncmp(line, "VmHWM:", 6) == 0) kb = std::strtoull(line + 6, nullptr, 10);
  }
  std::fclose(f);
  return kb * 1024;
}

double cpu_seconds_now() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

struct SplitMix {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
};

void token(char out[33], std::uint64_t a, std::uint64_t b) {
  std::snprintf(out, 33, "%016" PRIx64 "%016" PRIx64, a, b);
}

// Writes records shaped like real sample_data (json.dump indent=0 style, ~600 bytes each)
// until the file reaches `target_bytes`; one record buffer, nothing accumulated. `records`
// receives the number written.
std::uint64_t generate(const fs::path& file, std::uint64_t target_bytes, std::uint64_t* records = nullptr) {
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (f == nullptr) throw nsg::IoError(file.string(), "", "cannot create the benchmark table");
  std::setvbuf(f, nullptr, _IOFBF, 1 << 20);
  static const char* kChannels[] = {"LIDAR_TOP", "CAM_FRONT", "RADAR_FRONT", "CAM_BACK_LEFT"};
  SplitMix rng{42};
  std::uint64_t written = std::fprintf(f, "[\n");
  char tok[33], sample[33], cs[33], prev[33], next[33];
  std::uint64_t i = 0;
  for (; written < target_bytes; ++i) {
    const std::uint64_t key = rng.next();
    token(tok, key, i);
    token(sample, rng.next(), i / 20);
    token(cs, rng.next() % 120, 7);
    token(prev, key ^ 1, i - 1);
    token(next, key ^ 2, i + 1);
    const char* channel = kChannels[i % 4];
    const bool camera = channel[0] == 'C';
    const std::int64_t ts = 1532402927647951 + static_cast<std::int64_t>(i) * 50000;
    written += std::fprintf(f,
                            "%s{\n\"token\": \"%s\",\n\"sample_token\": \"%s\",\n\"ego_pose_token\": \"%s\",\n"
                            "\"calibrated_sensor_token\": \"%s\",\n\"timestamp\": %" PRId64
                            ",\n\"fileformat\": \"%s\",\n"
                            "\"is_key_frame\": %s,\n\"height\": %d,\n\"width\": %d,\n"
                            "\"filename\": \"%s/%s/n015-2018-07-24-11-22-45+0800__%s__%" PRId64
                            ".%s\",\n"
                            "\"prev\": \"%s\",\n\"next\": \"%s\"\n}",
                            i == 0 ? "" : ",\n", tok, sample, tok, cs, ts, camera ? "jpg" : "pcd",
                            i % 10 == 0 ? "true" : "false", camera ? 900 : 0, camera ? 1600 : 0,
                            i % 10 == 0 ? "samples" : "sweeps", channel, channel, ts, camera ? "jpg" : "pcd.bin",
                            i == 0 ? "" : prev, next);
  }
  written += std::fprintf(f, "\n]\n");
  if (std::ferror(f) != 0 || std::fclose(f) != 0) throw nsg::IoError(file.string(), "", "write failed (disk full?)");
  if (records != nullptr) *records = i;
  return written;
}

struct Measurement {
  double seconds = 0;
  double cpu_seconds = 0;  // user + sys of the load (the machine may be shared)
  std::uint64_t rss_before = 0;
  std::uint64_t rss_peak = 0;
  std::uint64_t records = 0;
  int ok = 0;
};

// Loads the table in a forked child (fresh peak-RSS accounting) and returns its figures.
Measurement measure_in_child(const fs::path& file) {
  int fds[2];
  if (::pipe(fds) != 0) throw nsg::InternalError("", "", "pipe failed");
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    Measurement m;
    m.rss_before = peak_rss_bytes();
    try {
      const double cpu_start = cpu_seconds_now();
      const auto start = std::chrono::steady_clock::now();
      const auto table = nsg::nuscenes::Table<nsg::nuscenes::SampleData>::load(file);
      m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      m.cpu_seconds = cpu_seconds_now() - cpu_start;
      m.records = table.size();
      m.rss_peak = peak_rss_bytes();
      m.ok = 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_nuscenes: %s\n", e.what());
    }
    if (::write(fds[1], &m, sizeof m) != static_cast<ssize_t>(sizeof m)) ::_exit(2);
    ::_exit(0);
  }
  ::close(fds[1]);
  Measurement m;
  const ssize_t n = ::read(fds[0], &m, sizeof m);
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (n != static_cast<ssize_t>(sizeof m) || !m.ok) throw nsg::InternalError("", "", "benchmark child failed");
  return m;
}

// Removes the benchmark table however the run ends (forked children leave with _exit).
struct RemoveOnExit {
  fs::path file;
  ~RemoveOnExit() {
    std::error_code ec;
    if (!file.empty()) fs::remove(file, ec);
  }
};

// The scale case: a table as large as (or larger than) the real trainval sample_data.json.
int run_scale(std::uint64_t target_mb, const fs::path& dir) {
  const fs::path file = dir / ("nsg-bench-scale-sample_data-" + std::to_string(::getpid()) + ".json");
  RemoveOnExit cleanup{file};
  std::uint64_t records = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t bytes = generate(file, target_mb * 1000 * 1000, &records);
  const double gen_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("bench_nuscenes scale: sample_data-shaped table %.1f MB (%" PRIu64 " records, written in %.1f s) at %s\n",
              bytes / 1e6, records, gen_s, file.c_str());
  std::fflush(stdout);
  const Measurement m = measure_in_child(file);
  const double mbps = bytes / 1e6 / m.seconds;
  const double ratio = static_cast<double>(m.rss_peak) / static_cast<double>(bytes);
  std::printf("bench_nuscenes scale: loaded %" PRIu64
              " records in %.2f s = %.0f MB/s (CPU %.2f s = %.0f MB/s); "
              "peak RSS %.1f MB = %.2fx file (%.1f MB before load)\n",
              m.records, m.seconds, mbps, m.cpu_seconds, bytes / 1e6 / m.cpu_seconds, m.rss_peak / 1e6, ratio,
              m.rss_before / 1e6);
  bool ok = true;
  if (m.records != records) {
    std::printf("bench_nuscenes scale: FAIL record count %" PRIu64 " (written %" PRIu64 ")\n", m.records, records);
    ok = false;
  }
  if (ratio > 1.0) {
    std::printf("bench_nuscenes scale: FAIL peak RSS %.2fx the file (limit 1.00x)\n", ratio);
    ok = false;
  }
  if (ok)
    std::printf("bench_nuscenes scale: PASS (records %" PRIu64 " = written; peak RSS %.2fx <= 1.00x)\n", records,
                ratio);
  return ok ? 0 : 1;
}

}  // namespace

int main() {
  try {
    if (const long scale_mb = env_long("NSG_BENCH_SCALE_MB", 0); scale_mb > 0) {
      const char* dir_env = std::getenv("NSG_BENCH_DIR");
      const fs::path dir = dir_env != nullptr && *dir_env ? fs::path(dir_env) : fs::temp_directory_path();
      fs::create_directories(dir);
      return run_scale(static_cast<std::uint64_t>(scale_mb), dir);
    }
    const std::uint64_t target = static_cast<std::uint64_t>(env_long("NSG_BENCH_MB", 320)) * 1000 * 1000;
    const int reps = static_cast<int>(env_long("NSG_BENCH_REPS", 3));
    const char* dir_env = std::getenv("NSG_BENCH_DIR");
    const fs::path dir = dir_env != nullptr && *dir_env ? fs::path(dir_env) : fs::temp_directory_path();
    fs::create_directories(dir);
    const fs::path file = dir / ("nsg-bench-sample_data-" + std::to_string(::getpid()) + ".json");
    std::uint64_t records = 0;
    const std::uint64_t bytes = generate(file, target, &records);
    std::printf("bench_nuscenes: sample_data-shaped table %.1f MB at %s\n", bytes / 1e6, file.c_str());
    double best_mbps = 0, best_cpu_mbps = 0, worst_ratio = 0;
    for (int r = 0; r < reps; ++r) {
      const Measurement m = measure_in_child(file);
      const double mbps = bytes / 1e6 / m.seconds;
      const double cpu_mbps = bytes / 1e6 / m.cpu_seconds;
      const double ratio = static_cast<double>(m.rss_peak) / static_cast<double>(bytes);
      best_mbps = std::max(best_mbps, mbps);
      best_cpu_mbps = std::max(best_cpu_mbps, cpu_mbps);
      worst_ratio = std::max(worst_ratio, ratio);
      if (m.records != records)
        throw nsg::InternalError(
            file.string(), "",
            "the loader read " + std::to_string(m.records) + " records of " + std::to_string(records) + " written");
      std::printf("  load %d: %" PRIu64
                  " records in %.3f s = %.0f MB/s (CPU %.3f s = %.0f MB/s); peak RSS %.1f MB (%.2fx file; %.1f MB "
                  "before load)\n",
                  r + 1, m.records, m.seconds, mbps, m.cpu_seconds, cpu_mbps, m.rss_peak / 1e6, ratio,
                  m.rss_before / 1e6);
    }
    std::printf(
        "bench_nuscenes: best %.0f MB/s wall, %.0f MB/s per CPU second (target >= 800); worst peak/file %.2f "
        "(target <= 2.00)\n",
        best_mbps, best_cpu_mbps, worst_ratio);
    if (std::getenv("NSG_BENCH_KEEP") == nullptr) fs::remove(file);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_nuscenes: error: %s\n", e.what());
    return 3;
  }
}

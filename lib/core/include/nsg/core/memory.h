#pragma once
// The process's memory as the kernel counts it (Linux /proc/self/status): what `generate`
// reports per stage and checks its estimate against, and size arguments ("16G").
#include <cstdint>
#include <string>

namespace nsg {

// Resident set size now, and its peak since the process started (VmRSS, VmHWM), in bytes;
// 0 where /proc is not available.
uint64_t current_rss_bytes();
uint64_t peak_rss_bytes();

// The memory this process may use: the machine's physical memory, or the cgroup's limit
// (cgroup v2 memory.max, as a Kubernetes pod or Slurm job sets it) when that is lower; 0
// when neither can be read.
uint64_t available_memory_bytes();

// "800M", "16G", "1.5GB", "2048" (bytes), "512KiB": decimal units for K/M/G/T(B), binary for
// KiB/MiB/GiB/TiB. Throws ConfigError naming `what` for anything else or a value ≤ 0.
uint64_t parse_memory_size(const std::string& text, const std::string& what);

}  // namespace nsg

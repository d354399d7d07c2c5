// Which share of a distributed run a process does: flags, Slurm array, Kubernetes Indexed Job.
#include <gtest/gtest.h>

#include <cstdlib>

#include "nsg/core/error.h"
#include "nsg/pipeline/generate.h"

namespace nsg::pipeline {
namespace {

struct EnvGuard {
  explicit EnvGuard(std::initializer_list<std::pair<const char*, const char*>> vars) {
    for (const char* name :
         {"SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_ARRAY_TASK_MIN", "JOB_COMPLETION_INDEX"})
      ::unsetenv(name);
    for (const auto& [k, v] : vars) ::setenv(k, v, 1);
  }
  ~EnvGuard() {
    for (const char* name :
         {"SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_ARRAY_TASK_MIN", "JOB_COMPLETION_INDEX"})
      ::unsetenv(name);
  }
};

TEST(Share, FlagsWinOverTheEnvironment) {
  EnvGuard env({{"SLURM_ARRAY_TASK_ID", "1"}, {"SLURM_ARRAY_TASK_COUNT", "4"}});
  const ShareSpec s = resolve_share(2, 3);
  EXPECT_EQ(s.index, 2);
  EXPECT_EQ(s.count, 3);
}

TEST(Share, SlurmArrayIncludingOneBasedArrays) {
  {
    EnvGuard env({{"SLURM_ARRAY_TASK_ID", "3"}, {"SLURM_ARRAY_TASK_COUNT", "4"}});
    const ShareSpec s = resolve_share(std::nullopt, std::nullopt);
    EXPECT_EQ(s.index, 3);
    EXPECT_EQ(s.count, 4);
  }
  EnvGuard env({{"SLURM_ARRAY_TASK_ID", "4"}, {"SLURM_ARRAY_TASK_COUNT", "4"}, {"SLURM_ARRAY_TASK_MIN", "1"}});
  EXPECT_EQ(resolve_share(std::nullopt, std::nullopt).index, 3);
}

TEST(Share, KubernetesIndexedJobNeedsAnExplicitCount) {
  EnvGuard env({{"JOB_COMPLETION_INDEX", "5"}});
  const ShareSpec s = resolve_share(std::nullopt, 8);
  EXPECT_EQ(s.index, 5);
  EXPECT_EQ(s.count, 8);
  EXPECT_EQ(resolve_share(std::nullopt, std::nullopt).count, 1);  // no count: a single run
}

TEST(Share, OutOfRangeIsAConfigError) {
  EnvGuard env({});
  EXPECT_THROW(resolve_share(3, 3), ConfigError);
  EXPECT_THROW(resolve_share(0, 0), ConfigError);
  EXPECT_THROW(resolve_share(1, std::nullopt), ConfigError);
  EnvGuard bad({{"SLURM_ARRAY_TASK_ID", "x"}, {"SLURM_ARRAY_TASK_COUNT", "2"}});
  EXPECT_THROW(resolve_share(std::nullopt, std::nullopt), ConfigError);
}

}  // namespace
}  // namespace nsg::pipeline

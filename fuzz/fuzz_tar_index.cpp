// The shard readers behind nsgraph.Dataset (index_tar: header-only pass, positioned reads)
// and validate / score (TarReader over libarchive): both must refuse the same archives
// cleanly, never loop or allocate from a hostile size, and agree on what they accept.
#include <cstdlib>

#include "fuzz_support.h"
#include "nsg/io/tar.h"
#include "nsg/io/tar_index.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file = nsg::fuzz::input_file(data, size);
  std::vector<nsg::io::TarIndexEntry> index;
  nsg::fuzz::expect_only_input_errors([&] {
    index = nsg::io::index_tar(file);
    for (const auto& e : index)
      if (e.offset > size || e.size > size - e.offset) std::abort();  // every member within the file
  });
  nsg::fuzz::expect_only_input_errors([&] {
    nsg::io::TarReader reader(file);
    nsg::io::TarMember m;
    while (reader.next(m)) {
    }
  });
  return 0;
}

// The table reader (read_table + Table::load): the first byte picks one of the 13 record
// types, the rest is the table file.
#include "fuzz_support.h"
#include "nsg/nuscenes/tables.h"

namespace {
template <class Record>
void load(const std::filesystem::path& file) {
  nsg::fuzz::expect_only_input_errors([&] { (void)nsg::nuscenes::Table<Record>::load(file); });
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace nsg::nuscenes;
  if (size < 1) return 0;
  const std::filesystem::path file = nsg::fuzz::input_file(data + 1, size - 1);
  switch (data[0] % 13) {
    case 0: load<Category>(file); break;
    case 1: load<Attribute>(file); break;
    case 2: load<Visibility>(file); break;
    case 3: load<Sensor>(file); break;
    case 4: load<CalibratedSensor>(file); break;
    case 5: load<EgoPose>(file); break;
    case 6: load<Log>(file); break;
    case 7: load<Map>(file); break;
    case 8: load<Scene>(file); break;
    case 9: load<Sample>(file); break;
    case 10: load<SampleData>(file); break;
    case 11: load<SampleAnnotation>(file); break;
    default: load<Instance>(file); break;
  }
  return 0;
}

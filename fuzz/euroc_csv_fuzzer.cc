// Fuzz target: the EuRoC ASL csv readers (io/euroc_dataset.h on top of io/text_rows.h). The
// input is one data.csv that the camera list, IMU and ground-truth readers each parse; what
// they accept then goes through the image-stream and gap checks EurocDataset::Open applies.
// Bad input must end in InputError (file and line); anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/util/error.h"
#include "fuzz/fuzz_support.h"
#include "io/dataset_common.h"
#include "io/euroc_dataset.h"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  pkslam::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pkslam;
  const auto csv = fuzz::WriteScratchFile("data.csv", data, size);

  try {
    const std::vector<ImageEntry> listed = ReadEurocImageList(csv, fuzz::ScratchDir() / "data");
    ImageStream stream;
    stream.name = "cam0";
    stream.list_file = csv;
    stream.nominal_rate_hz = 20;
    FillImageStream(listed, 1.5, &stream);
    // Few listed images exist here: the gap checks on the list as if they all did, against
    // the nominal rate and against the median interval.
    std::vector<std::int64_t> t_ns;
    for (const ImageEntry& e : listed) t_ns.push_back(e.t_ns);
    FindTimeGaps(t_ns, 1e9 / 20, 1.5);
    FindTimeGaps(t_ns, 0, 1.5);
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }

  try {
    const std::vector<ImuSample> imu = ReadEurocImu(csv);
    std::vector<std::int64_t> t_ns;
    for (const ImuSample& s : imu) t_ns.push_back(s.t_ns);
    FindTimeGaps(t_ns, 1e9 / 200, 2.5);
    FindTimeGaps(t_ns, 0, 2.5);
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }

  try {
    ReadEurocGroundTruth(csv);
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  return 0;
}

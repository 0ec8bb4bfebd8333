// The `noise:` block (imufit/io/noise_file.h) as a document and from a YAML tree: what
// noise_file.cc writes and reads, and calibration.cc embeds.
#ifndef IMUFIT_IO_SRC_NOISE_YAML_H_
#define IMUFIT_IO_SRC_NOISE_YAML_H_

#include "imufit/io/machine_text.h"
#include "imufit/io/noise_file.h"
#include "yaml_util.h"

namespace imufit {

// The block's value (the map under `noise:`).
MachineDoc NoiseDoc(const NoiseRecord& record);
// Reads a block; throws InputError located at a key whose value has the wrong type, at a `format`
// other than imufit-noise or a `version` above 1.
NoiseRecord ReadNoiseRecord(const yaml::Located& block);

}  // namespace imufit

#endif  // IMUFIT_IO_SRC_NOISE_YAML_H_

// The `fit:` and `check:` blocks of a calibration file (imufit/io/fit_record.h) as YAML: what
// calibration.cc writes and reads.
#ifndef IMUFIT_IO_SRC_FIT_RECORD_YAML_H_
#define IMUFIT_IO_SRC_FIT_RECORD_YAML_H_

#include <yaml-cpp/yaml.h>

#include "imufit/io/fit_record.h"
#include "imufit/io/machine_text.h"
#include "yaml_util.h"

namespace imufit {

// The block as a document, its keys in the table's order, then `extra`'s.
MachineDoc FitRecordDoc(const FitRecord& record);
MachineDoc CheckRecordDoc(const CheckRecord& record);

// Reads a block; throws InputError located at a key whose value has the wrong type.
FitRecord ReadFitRecord(const yaml::Located& block);
CheckRecord ReadCheckRecord(const yaml::Located& block);

}  // namespace imufit

#endif  // IMUFIT_IO_SRC_FIT_RECORD_YAML_H_

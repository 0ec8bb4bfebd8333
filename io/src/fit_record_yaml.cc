#include "fit_record_yaml.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "imufit/base/robust_loss.h"
#include "imufit/io/error.h"
#include "imufit/model/sensor_model.h"

namespace imufit {
namespace {

// ---------------------------------------------------------------- the tables, visited

#define IMUFIT_RECORD_VISIT(type, key, description) visit(#key, record.key);

// visit(key, member) for every member of a record, in the table's order (Record may be const).
template <typename Record, typename Visit>
void VisitFitRecord(Record& record, Visit&& visit) {
  IMUFIT_FIT_RECORD_FIELDS(IMUFIT_RECORD_VISIT)
}

template <typename Record, typename Visit>
void VisitFieldRecord(Record& record, Visit&& visit) {
  IMUFIT_FIELD_RECORD_FIELDS(IMUFIT_RECORD_VISIT)
}

template <typename Record, typename Visit>
void VisitCheckRecord(Record& record, Visit&& visit) {
  IMUFIT_CHECK_RECORD_FIELDS(IMUFIT_RECORD_VISIT)
}

#undef IMUFIT_RECORD_VISIT

// ---------------------------------------------------------------- writing

MachineDoc ValueDoc(const std::string& value) { return MachineDoc::Text(value); }
MachineDoc ValueDoc(long long value) { return MachineDoc::Integer(value); }
MachineDoc ValueDoc(int value) { return MachineDoc::Integer(value); }
MachineDoc ValueDoc(bool value) { return MachineDoc::Bool(value); }
MachineDoc ValueDoc(double value) { return MachineDoc::Number(value); }
// Temperatures one a line; names and ids on one line.
MachineDoc ValueDoc(const std::vector<double>& values) {
  return MachineDoc::Numbers(values, MachineDoc::Style::kBlock);
}
MachineDoc ValueDoc(const std::vector<int>& values) { return MachineDoc::Integers(values); }
MachineDoc ValueDoc(const std::vector<std::string>& values) { return MachineDoc::Texts(values); }
MachineDoc ValueDoc(const FieldRecord& record);  // a block of its own, below

template <typename Record, typename VisitRecord>
MachineDoc RecordDoc(const Record& record, VisitRecord visit_record) {
  MachineDoc doc = MachineDoc::Map();
  visit_record(record, [&doc](const char* key, const auto& member) {
    if (member) doc.Add(key, ValueDoc(*member));
  });
  if (record.extra.IsMap()) {
    for (const auto& entry : record.extra) doc.Add(entry.first.Scalar(), MachineDocOfYaml(entry.second));
  }
  return doc;
}

// ---------------------------------------------------------------- reading

void Get(const yaml::Located& value, std::string* out) { *out = value.String(); }
void Get(const yaml::Located& value, long long* out) { *out = value.Integer(); }
void Get(const yaml::Located& value, bool* out) { *out = value.Bool(); }

void Get(const yaml::Located& value, int* out) {
  const long number = value.Integer();
  if (number < std::numeric_limits<int>::min() || number > std::numeric_limits<int>::max()) {
    value.Fail(std::to_string(number) + " is out of range");
  }
  *out = static_cast<int>(number);
}

// A number; also what the writer writes for a value that is not finite (.nan, .inf, -.inf).
void Get(const yaml::Located& value, double* out) {
  if (value.node.IsScalar()) {
    const std::string& text = value.node.Scalar();
    if (text == ".nan" || text == ".NaN" || text == ".NAN") {
      *out = std::numeric_limits<double>::quiet_NaN();
      return;
    }
    const bool negative = text.size() > 1 && text[0] == '-';
    const std::string magnitude = negative || (!text.empty() && text[0] == '+') ? text.substr(1) : text;
    if (magnitude == ".inf" || magnitude == ".Inf" || magnitude == ".INF") {
      *out = negative ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
      return;
    }
  }
  *out = value.Double();
}

template <typename T>
void Get(const yaml::Located& value, std::vector<T>* out) {
  const size_t count = value.Size();
  out->clear();
  for (size_t i = 0; i < count; ++i) {
    T item{};
    Get(value.At(i), &item);
    out->push_back(std::move(item));
  }
}

void Get(const yaml::Located& value, FieldRecord* out);  // a block of its own, below

template <typename Record, typename VisitRecord>
Record ReadRecord(const yaml::Located& block, VisitRecord visit_record) {
  block.RequireMap();
  Record record;
  std::set<std::string> known;
  visit_record(record, [&](const char* key, auto& member) {
    known.insert(key);
    if (!block.Has(key)) return;
    typename std::decay_t<decltype(member)>::value_type value{};
    Get(block[key], &value);
    member = std::move(value);
  });
  for (const auto& entry : block.node) {
    if (known.count(entry.first.Scalar()) > 0) continue;
    if (!record.extra.IsMap()) record.extra = YAML::Node(YAML::NodeType::Map);
    record.extra.force_insert(entry.first, entry.second);
  }
  return record;
}

MachineDoc ValueDoc(const FieldRecord& record) {
  return RecordDoc(record, [](const FieldRecord& r, auto&& visit) { VisitFieldRecord(r, visit); });
}

void Get(const yaml::Located& value, FieldRecord* out) {
  *out = ReadRecord<FieldRecord>(value, [](FieldRecord& r, auto&& visit) { VisitFieldRecord(r, visit); });
}

// The coefficient groups a fit estimates or holds, as the record names them: "gyro.bias", ...,
// "accel.misalignment" (the model's groups of each sensor, model/sensor_model.h).
std::vector<std::string> GroupNames() {
  std::vector<std::string> names;
  for (const bool gyro : {true, false}) {
    const int coefficients = gyro ? kGyroCoefficients : kAccelCoefficients;
    for (int c = 0; c < coefficients; ++c) {
      const std::string name = std::string(gyro ? "gyro." : "accel.") + kCoefficientNames[c].group;
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
  }
  return names;
}

// Refuses a loss or a group the fit does not know, at its line and column.
void CheckFitOptionNames(const yaml::Located& block, const FitRecord& record) {
  if (record.loss) {
    RobustLoss loss = RobustLoss::kHuber;
    std::string error;
    if (!ParseRobustLoss(*record.loss, &loss, &error)) block["loss"].Fail(error);
  }
  const std::vector<std::string> groups = GroupNames();
  for (const auto& [key, names] : {std::pair{"fitted", &record.fitted}, {"held", &record.held}}) {
    if (!*names) continue;
    for (size_t i = 0; i < (*names)->size(); ++i) {
      const std::string& name = (**names)[i];
      if (std::find(groups.begin(), groups.end(), name) != groups.end()) continue;
      std::string list;
      for (const std::string& group : groups) list += (list.empty() ? "" : ", ") + group;
      block[key].At(i).Fail(QuoteForMessage(name) + " is not a coefficient group (" + list + ")");
    }
  }
  if (record.uncalibrated_sensors) {
    for (size_t i = 0; i < record.uncalibrated_sensors->size(); ++i) {
      const std::string& name = (*record.uncalibrated_sensors)[i];
      if (name != "gyro" && name != "accel")
        block["uncalibrated_sensors"].At(i).Fail(QuoteForMessage(name) + " is not a sensor (gyro, accel)");
    }
  }
}

}  // namespace

MachineDoc FitRecordDoc(const FitRecord& record) {
  return RecordDoc(record, [](const FitRecord& r, auto&& visit) { VisitFitRecord(r, visit); });
}

MachineDoc CheckRecordDoc(const CheckRecord& record) {
  return RecordDoc(record, [](const CheckRecord& r, auto&& visit) { VisitCheckRecord(r, visit); });
}

FitRecord ReadFitRecord(const yaml::Located& block) {
  FitRecord record =
      ReadRecord<FitRecord>(block, [](FitRecord& r, auto&& visit) { VisitFitRecord(r, visit); });
  CheckFitOptionNames(block, record);
  return record;
}

CheckRecord ReadCheckRecord(const yaml::Located& block) {
  return ReadRecord<CheckRecord>(block, [](CheckRecord& r, auto&& visit) { VisitCheckRecord(r, visit); });
}

}  // namespace imufit

#include "fit_record_yaml.h"

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

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
void VisitCheckRecord(Record& record, Visit&& visit) {
  IMUFIT_CHECK_RECORD_FIELDS(IMUFIT_RECORD_VISIT)
}

#undef IMUFIT_RECORD_VISIT

// ---------------------------------------------------------------- writing

template <typename T>
void Put(YAML::Node* node, const char* key, const T& value) {
  (*node)[key] = value;
}

// Names and ids on one line.
template <typename T>
void PutFlowList(YAML::Node* node, const char* key, const std::vector<T>& values) {
  YAML::Node list(YAML::NodeType::Sequence);
  for (const T& value : values) list.push_back(value);
  list.SetStyle(YAML::EmitterStyle::Flow);
  (*node)[key] = list;
}
void Put(YAML::Node* node, const char* key, const std::vector<int>& values) {
  PutFlowList(node, key, values);
}
void Put(YAML::Node* node, const char* key, const std::vector<std::string>& values) {
  PutFlowList(node, key, values);
}

template <typename Record, typename VisitRecord>
YAML::Node RecordNode(const Record& record, VisitRecord visit_record) {
  YAML::Node node(YAML::NodeType::Map);
  visit_record(record, [&node](const char* key, const auto& member) {
    if (member) Put(&node, key, *member);
  });
  if (record.extra.IsMap()) {
    for (const auto& entry : record.extra) node.force_insert(entry.first, entry.second);
  }
  return node;
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

}  // namespace

YAML::Node FitRecordNode(const FitRecord& record) {
  return RecordNode(record, [](const FitRecord& r, auto&& visit) { VisitFitRecord(r, visit); });
}

YAML::Node CheckRecordNode(const CheckRecord& record) {
  return RecordNode(record, [](const CheckRecord& r, auto&& visit) { VisitCheckRecord(r, visit); });
}

FitRecord ReadFitRecord(const yaml::Located& block) {
  return ReadRecord<FitRecord>(block, [](FitRecord& r, auto&& visit) { VisitFitRecord(r, visit); });
}

CheckRecord ReadCheckRecord(const yaml::Located& block) {
  return ReadRecord<CheckRecord>(block, [](CheckRecord& r, auto&& visit) { VisitCheckRecord(r, visit); });
}

}  // namespace imufit

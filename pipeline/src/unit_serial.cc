#include "imufit/pipeline/unit_serial.h"

#include "imufit/io/error.h"
#include "imufit/io/samples.h"

namespace imufit {

namespace {

SerialSource HeaderSource(const std::string& samples_path, const SamplesSerial& found) {
  SerialSource source;
  source.kind = SerialSource::Kind::kHeader;
  source.name = "the samples header of " + samples_path;
  source.serial = found.serial;
  source.file = samples_path;
  source.line = found.line;
  source.column = found.column;
  return source;
}

}  // namespace

SerialSource SamplesHeaderSerial(const std::string& samples_path) {
  return HeaderSource(samples_path, LocateSamplesSerial(samples_path));
}

SerialSource SamplesHeaderSerial(const std::string& samples_name, const SamplesSerial& found) {
  return HeaderSource(samples_name, found);
}

SerialSource SamplesHeaderSerial(const SamplesReader& reader) {
  return HeaderSource(reader.path(), reader.located_serial());
}

UnitSerial ResolveSerial(const std::vector<SerialSource>& sources, bool allow_mismatch) {
  UnitSerial result;
  const SerialSource* chosen = nullptr;
  for (const SerialSource& source : sources) {
    if (source.serial.empty()) continue;
    if (chosen == nullptr) {
      chosen = &source;
      result.serial = source.serial;
      continue;
    }
    if (source.serial == chosen->serial) continue;
    const std::string disagreement = source.name + " names the unit " + QuoteForMessage(source.serial) +
                                     ", " + chosen->name + " names it " + QuoteForMessage(chosen->serial);
    const bool contradicts_header =
        chosen->kind == SerialSource::Kind::kStated && source.kind == SerialSource::Kind::kHeader;
    if (contradicts_header && !allow_mismatch) {
      throw InputError(source.file, source.line, source.column,
                       disagreement + ": are these that unit's samples? (--allow-mismatch uses " +
                           QuoteForMessage(chosen->serial) + " anyway)");
    }
    result.warnings.push_back(disagreement + ": " + QuoteForMessage(chosen->serial) + " is used" +
                              (contradicts_header ? " (allowed with --allow-mismatch)" : ""));
  }
  return result;
}

}  // namespace imufit

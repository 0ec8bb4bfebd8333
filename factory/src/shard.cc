#include "imufit/factory/shard.h"

#include <cstdlib>

#include "imufit/io/error.h"

namespace imufit {
namespace {

constexpr const char* kWhere = "--shard";

// A whole number >= 0 from `text`; -1 when it is not one.
long long WholeNumber(const char* text) {
  if (text == nullptr || *text == '\0') return -1;
  char* end = nullptr;
  const long long value = std::strtoll(text, &end, 10);
  return (*end == '\0' && value >= 0 && value < (1LL << 30)) ? value : -1;
}

[[noreturn]] void Refuse(const std::string& why) { throw InputError(kWhere, why); }

long long FromEnvironment(const Environment& environment, const char* name) {
  const char* value = environment(name);
  const long long number = WholeNumber(value);
  if (value != nullptr && number < 0) Refuse(std::string(name) + "=\"" + value + "\" is not a whole number");
  return number;
}

// The index the scheduler gives this task; -1 when no scheduler's variable is set.
long long ScheduledIndex(const Environment& environment) {
  const long long k8s = FromEnvironment(environment, "JOB_COMPLETION_INDEX");
  if (k8s >= 0) return k8s;
  const long long parallel = FromEnvironment(environment, "PARALLEL_SEQ");
  if (parallel >= 1) return parallel - 1;  // GNU parallel counts from 1
  const long long slurm = FromEnvironment(environment, "SLURM_ARRAY_TASK_ID");
  if (slurm < 0) return -1;
  const long long minimum = FromEnvironment(environment, "SLURM_ARRAY_TASK_MIN");
  return slurm - (minimum < 0 ? 0 : minimum);
}

}  // namespace

Shard ParseShard(const std::string& text, const Environment& environment) {
  long long index = -1, count = -1;
  const size_t slash = text.find('/');
  const std::string first = text.substr(0, slash);
  if (slash != std::string::npos) count = WholeNumber(text.c_str() + slash + 1);
  if (first == "auto") {
    if (slash == std::string::npos) {
      count = FromEnvironment(environment, "SLURM_ARRAY_TASK_COUNT");
      if (count < 0) Refuse("auto without a count needs SLURM_ARRAY_TASK_COUNT (else give auto/N)");
    }
    index = ScheduledIndex(environment);
    if (index < 0) {
      Refuse("auto: none of JOB_COMPLETION_INDEX, PARALLEL_SEQ, SLURM_ARRAY_TASK_ID is set");
    }
  } else {
    index = WholeNumber(first.c_str());
  }
  if (index < 0 || count < 1) Refuse("\"" + text + "\" is not I/N, auto or auto/N");
  if (index >= count) {
    Refuse("shard index " + std::to_string(index) + " is not below the count " + std::to_string(count));
  }
  return {static_cast<int>(index), static_cast<int>(count)};
}

int ShardOf(const std::string& unit_name, int count) {
  uint64_t hash = 0xcbf29ce484222325ULL;
  for (const unsigned char c : unit_name) {
    hash ^= c;
    hash *= 0x100000001b3ULL;
  }
  return static_cast<int>(hash % static_cast<uint64_t>(count));
}

}  // namespace imufit

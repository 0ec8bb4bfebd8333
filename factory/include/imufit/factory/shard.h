// imufit — a batch split across the tasks of a scheduler: `imufit batch --shard I/N` takes the
// units whose stable hash (of the unit folder's name) modulo N is I; `--shard auto` reads I and N
// from the scheduler (docs/scale.md).
#ifndef IMUFIT_FACTORY_SHARD_H_
#define IMUFIT_FACTORY_SHARD_H_

#include <cstdint>
#include <functional>
#include <string>

namespace imufit {

struct Shard {
  int index = 0;  // 0 <= index < count
  int count = 1;  // 1: the whole lot
};

// Reads an environment variable; nullptr when it is not set.
using Environment = std::function<const char*(const char*)>;

// "I/N" (0 <= I < N); "auto" (Slurm job arrays: SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN of
// SLURM_ARRAY_TASK_COUNT); "auto/N" with the count given (a Kubernetes Indexed Job's
// JOB_COMPLETION_INDEX, else GNU parallel's PARALLEL_SEQ - 1, else Slurm's task). InputError
// (naming --shard) for anything else, and for an index outside 0..N-1.
Shard ParseShard(const std::string& text, const Environment& environment);

// The shard a unit belongs to: FNV-1a (64 bit) of its folder's name, modulo the count. The same on
// every machine and in every run.
int ShardOf(const std::string& unit_name, int count);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_SHARD_H_

// imufit — how many times io has opened a file to read it. A run's samples file can be large (an
// hour at 1 kHz), so commands read it as few times as their work needs (`imufit fit --report
// --store`: at most twice); tests hold them to it with this count.
//
// Counted per file, by its identity (device and inode: two spellings of a path are one file), by
// every io reader that opens a file itself: CsvReader (samples, series) and Sha256OfFile.
#ifndef IMUFIT_IO_FILE_READS_H_
#define IMUFIT_IO_FILE_READS_H_

#include <string>

namespace imufit {

// How many times the file `path` names has been opened for reading by io in this process; 0 for a
// file never opened, or one that does not exist.
long long TimesOpenedForReading(const std::string& path);

// Counts one opening of the file `path` names (io's readers call it once they have opened it).
void CountOpenedForReading(const std::string& path);

}  // namespace imufit

#endif  // IMUFIT_IO_FILE_READS_H_

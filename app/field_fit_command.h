// imufit fit --field — a calibration from a session by hand, without a table or a plan
// (pipeline/field_run.h, docs/field.md). `fit` declares the options and hands the run over here.
#ifndef IMUFIT_APP_FIELD_FIT_COMMAND_H_
#define IMUFIT_APP_FIELD_FIT_COMMAND_H_

#include <functional>
#include <string>
#include <vector>

#include "cli_options.h"
#include "commands.h"
#include "imufit/fit/field_fit.h"
#include "imufit/pipeline/field_run.h"
#include "imufit/pipeline/fit_run.h"

namespace imufit {

struct FieldFitArguments {
  bool field = false;                   // --field: a session by hand
  CliOptions<FieldFitOptions> options;  // FieldFitOptionTable()
  std::string repeat;                   // --repeat: a second session of the unit, compared
  LogTopics topics;                     // --topic, --temp-topic: a ROS bag's topics
  std::vector<double> session_temps_c;  // --session-temp-c: each session's temperature, in order
  std::string instance;                 // --instance: a PX4 ULog's sensor instance (multi_id)
};

// Adds --field and the field fit's own options (which need it) to `command`.
void AddFieldFitOptions(CliCommand command, FieldFitArguments* args);

// Refuses (InputError, exit 2) a table fit's option given with --field that has no meaning for a
// session by hand (--validate, --prior, --fit, ...).
void RefuseTableOptions(const FitRunArguments& run);

// The field fit of `samples` (one session, or several of one unit fitted jointly) written to
// `output`; `run` gives how the samples are read (--temp-c, --time-unit, columns, rest detection)
// and whether the g-sensitivity is fitted (--no-g-sensitivity). With --repeat (one session only),
// the second session is fitted alike and compared (CompareFieldFits); the file is the first
// session's. Returns the exit status: 0, or 1 when the sessions do not determine the model (the
// message says what they lack), disagree (a session's biases off the joint fit), or the fit does
// not converge; nothing is written then.
// `certify`, when given (fit --field --limits/--report/--store), takes the usable fit in place of
// writing the calibration (it certifies, judges, writes and records it: CertifyUnit) and returns
// the exit status.
int RunFieldFit(const FieldFitArguments& args, const std::vector<std::string>& samples,
                const std::string& output, const std::string& serial, bool quiet, const FitRunOptions& run,
                const std::function<int(const FieldRunResult&)>& certify = {});

}  // namespace imufit

#endif  // IMUFIT_APP_FIELD_FIT_COMMAND_H_

// imufit — the git revision this build was made from, for certificates, lot pages and --version.
#ifndef IMUFIT_FACTORY_GIT_REVISION_H_
#define IMUFIT_FACTORY_GIT_REVISION_H_

namespace imufit {

// The short revision ("unknown" outside a git checkout), as configured. It lives in one generated
// source (factory/src/git_revision.cc.in), so that a new revision recompiles that file alone.
const char* GitRevision();

}  // namespace imufit

#endif  // IMUFIT_FACTORY_GIT_REVISION_H_

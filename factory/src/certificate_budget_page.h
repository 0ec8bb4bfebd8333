// The certificate's metrology sections (certificate_page.cc places them): the uncertainty budget,
// what U covers and what it does not.
#ifndef IMUFIT_FACTORY_SRC_CERTIFICATE_BUDGET_PAGE_H_
#define IMUFIT_FACTORY_SRC_CERTIFICATE_BUDGET_PAGE_H_

#include "imufit/factory/certificate.h"
#include "imufit/report/html.h"

namespace imufit::internal {

// The budget's top contributors per class of figures, the Type B sources declared, the statements.
void BudgetSection(Html* h, const Certificate& c);
// The decision rule the verdict applied, and how many criteria are conditional.
void DecisionRuleNote(Html* h, const Verdict& verdict);

}  // namespace imufit::internal

#endif  // IMUFIT_FACTORY_SRC_CERTIFICATE_BUDGET_PAGE_H_

#include "certificate_budget_page.h"

#include "page.h"

namespace imufit::internal {
namespace {

void Sources(Html* h, const UncertaintyBudget& budget) {
  if (budget.inputs.empty()) return;
  h->Open("table", {{"data-key", "budget_sources"}}).Open("thead");
  Row(h, {"Type B source", "u as declared", "standard uncertainty u", "taken from"}, "th");
  h->Close("thead").Open("tbody");
  for (const StationUncertainty& s : budget.inputs) {
    std::string title = s.key;
    for (const StationInfluenceInfo& info : kStationUncertainties) {
      if (info.influence == s.influence) title = info.title;
    }
    h->Open("tr").Element("td", title);
    Num(h, Fmt("%.4g", s.written) + " " + s.unit + (s.rectangular ? " half width (rectangular)" : ""));
    Num(h, Fmt("%.4g", s.rectangular ? s.written / 1.7320508075688772 : s.written) + " " + s.unit);
    h->Element("td", s.source).Close("tr");
  }
  h->Close("tbody").Close("table");
}

}  // namespace

void DecisionRuleNote(Html* h, const Verdict& verdict) {
  std::string text = "Decision rule: " + verdict.RuleText();
  if (verdict.Conditional() > 0) {
    text += " " + Count(verdict.Conditional()) + " of " +
            Count(static_cast<long long>(verdict.criteria.size())) + " criteria are conditional.";
  }
  h->Element("p", text, {{"data-key", "decision_rule"}});
}

void BudgetSection(Html* h, const Certificate& c) {
  const UncertaintyBudget& budget = c.budget;
  h->Open("div", {{"class", "keep"}, {"data-key", "budget"}});
  h->Element("h2", "Uncertainty budget");
  h->Element("p", budget.covers, {{"data-key", "budget_covers"}});
  h->Element("p", budget.not_covered, {{"data-key", "budget_not_covered"}});
  Sources(h, budget);
  h->Open("table").Open("thead");
  Row(h, {"figures", "Type A (fit), RMS over axes", "largest Type B contributions, RMS over axes", "unit"},
      "th");
  h->Close("thead").Open("tbody");
  for (const BudgetClass& k : budget.classes) {
    std::string top;
    for (const BudgetClassLine& line : k.top) {
      top += (top.empty() ? "" : "; ") + line.source + " " + Fmt("%.2g", line.rms);
    }
    h->Open("tr", {{"data-budget-class", k.quantity}}).Element("td", FigureTitle(k.quantity));
    Num(h, Fmt("%.2g", k.type_a_rms));
    h->Element("td", top.empty() ? "none declared" : top).Element("td", k.unit).Close("tr");
  }
  h->Close("tbody").Close("table");
  h->Element("p",
             c.field
                 ? "The contribution of gravity is the change of the figure with gravity off by one standard "
                   "uncertainty (GUM 5.1.3): the field fit's cost is unchanged when gravity, the "
                   "accelerometer's scale factors and the gyro's g-sensitivity scale together, so the "
                   "change is exact; it and the fit's own uncertainty add in quadrature; U = 2 u_c."
                 : "Each contribution is the change of the figure when the fit is solved again with the "
                   "plan's truth off by one standard uncertainty of the source (GUM 5.1.3); the "
                   "contributions and the fit's own uncertainty add in quadrature; U = 2 u_c.",
             {{"class", "note"}});
  h->Close("div");
}

}  // namespace imufit::internal

#pragma once
// Linear forms of the parameters f = sum_i c_i theta_i, over one block (the a_i, the b_j or the free gamma_k),
// that the branch and bound bounds (and, for the dynamics, halves) besides the parameters.
//
// D is typically thin along directions the data leave ill-determined (on the paper-001 example a1 and a2 move
// together: a1 - a2 spreads a tenth as far as either; b1 and b2 with correlation 1.0000). Axis-aligned boxes
// cover such a strip poorly: every box holds mostly empty corners, and a product's relaxation is only as tight
// as its factors' ranges are narrow. A form across the strip, with its own range, cuts the corners away:
//  - a dynamics form multiplies the band factors of z_tau as a_i does (f z_tau = sum_i c_i a_i z_tau is linear in
//    the lifted products w_{i,tau});
//  - a gain form (over the b_j) and a shape form (over gamma_2..) multiply the other side of beta_jk = b_j gamma_k
//    (f gamma_k = sum_j c_j beta_jk is linear in beta), with McCormick envelopes over the form's narrow range.
//
// A box with forms has layout.count() + forms entries: the parameters, then the forms' ranges.
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "exact/interval.hpp"

namespace hw::exact {

struct LiftedData;
using ParamBox = std::vector<Interval>;

enum class FormBlock { kDynamics, kGain, kShape };  // over a_1..a_na; over the b_j; over gamma_2..gamma_ng
std::string ToString(FormBlock block);

struct ParameterForm {
  FormBlock block = FormBlock::kDynamics;
  std::vector<double> coef;  // one per entry of the block, in layout order (exact doubles)
  bool operator==(const ParameterForm& o) const { return block == o.block && coef == o.coef; }
};

struct FormOptions {
  // A principal direction of the points becomes a form when its spread is at most this share of the smallest
  // spread along an axis of its block.
  double thin_share = 0.5;
  bool gain = true;    // look for gain forms too (over the b_j): measured to pay (docs/exact_set.md)
  bool shape = false;  // look for shape forms too (over gamma_2..)
  bool IsValid(std::string* error) const;
};

// The layout entries of a block: [first, first + count).
std::pair<int, int> BlockEntries(const LiftedData& data, FormBlock block);

// The thin principal directions of the points' coordinates in each asked block (dynamics first; points in layout
// order; a block needs at least two entries and entries + 1 points). Coefficients are rounded to 2^-20 and
// scaled so the largest is 1: exact and reproducible.
std::vector<ParameterForm> ThinDirections(const LiftedData& data, const std::vector<std::vector<double>>& points,
                                          const FormOptions& options = {});

// The form's value at a point (layout order).
double FormValue(const LiftedData& data, const ParameterForm& form, const std::vector<double>& theta);
// The range of a form over its block's entries of a box (interval arithmetic: contains every value).
Interval FormRange(const LiftedData& data, const ParameterForm& form, const ParamBox& box);
// The box with the forms' ranges appended (a box that already has them is returned as it is).
ParamBox WithFormRanges(const LiftedData& data, const ParamBox& box);
// Narrows the block entries and form entries against each other (each range intersected with what the others
// imply); a range whose intersection would be empty is left as it was (the LP decides such a box).
void PropagateForms(const LiftedData& data, ParamBox& box);
// Whether box entry k is an a_i or a dynamics form's range.
bool IsDynamicsEntry(const LiftedData& data, int k);

// A dynamics form is written as its coefficient list (the format of results written before the other blocks
// existed); the others as {"block": ..., "coef": [...]}.
nlohmann::json FormsToJson(const std::vector<ParameterForm>& forms);
std::vector<ParameterForm> FormsFromJson(const nlohmann::json& j);

}  // namespace hw::exact

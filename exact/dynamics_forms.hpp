#pragma once
// Linear forms of the dynamics f = sum_i c_i a_i that the branch and bound may bound and halve besides the a_i.
//
// D's projection on (a_1..a_na) is typically a thin strip along a direction the data leave ill-determined (on
// the paper-001 example a1 and a2 move together: a1 - a2 spreads a tenth as far as either). Axis-aligned
// boxes cover such a strip poorly: every box holds mostly empty corners, and the relaxation of the products
// a_i z_{t-i} is only as tight as the box is small. A form across the strip, with its own range, cuts the
// corners away: the lifted LP multiplies (f - l) and (u - f) by the band factors of z_tau as it does (a_i - l_i)
// (f z_tau = sum_i c_i a_i z_tau is linear in the lifted products), so a narrow form range tightens the
// relaxation as a small box would.
//
// A box with forms has layout.count() + forms entries: the parameters, then the forms' ranges.
#include <vector>

#include <nlohmann/json.hpp>

#include "exact/interval.hpp"

namespace hw::exact {

struct LiftedData;
using ParamBox = std::vector<Interval>;

// Coefficients c_1..c_na of one form (exact doubles; any values give a valid relaxation).
using DynamicsForm = std::vector<double>;

struct DynamicsFormOptions {
  // A principal direction of the points becomes a form when its spread is at most this share of the smallest
  // spread along an axis a_i.
  double thin_share = 0.5;
  bool IsValid(std::string* error) const;
};

// The thin principal directions of the points' a-coordinates (points in layout order; at least na + 1 of
// them, else none). Coefficients are rounded to 2^-20 and scaled so the largest is 1: exact and reproducible.
std::vector<DynamicsForm> ThinDirections(const LiftedData& data, const std::vector<std::vector<double>>& points,
                                         const DynamicsFormOptions& options = {});

// The form's value at a point (layout order).
double FormValue(const LiftedData& data, const DynamicsForm& form, const std::vector<double>& theta);
// The range of a form over the a-entries of a box (interval arithmetic: contains every value).
Interval FormRange(const LiftedData& data, const DynamicsForm& form, const ParamBox& box);
// The box with the forms' ranges appended (a box that already has them is returned as it is).
ParamBox WithFormRanges(const LiftedData& data, const ParamBox& box);
// Narrows the a-entries and form entries against each other (each range intersected with what the others imply);
// a range whose intersection would be empty is left as it was (the LP decides such a box).
void PropagateForms(const LiftedData& data, ParamBox& box);

nlohmann::json FormsToJson(const std::vector<DynamicsForm>& forms);
std::vector<DynamicsForm> FormsFromJson(const nlohmann::json& j);

}  // namespace hw::exact

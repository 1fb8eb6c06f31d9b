#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "autograv/error.h"
#include "autograv/map/field_fit.h"
#include "choice_option.h"

namespace autograv::cli {

/// FieldModel from its name (toString), or autograv::Error listing the names.
inline FieldModel parseFieldModelName(const std::string& name) {
  FieldModel model = FieldModel::kChoose;
  if (!parseFieldModel(name, model)) {
    throw Error("unknown field model '" + name +
                "'; valid: choose, conservative, componentwise, corrected, thin_plate");
  }
  return model;
}

/// Adds --field-model choose|conservative|componentwise|corrected|thin_plate to `command`: how the
/// saved map reads the field between its measurements, written into `model` (choose, the
/// library's default, when the option is not given). The one definition shared by calibrate and
/// wizard.
inline CLI::Option* addFieldModelOption(CLI::App& command, FieldModel& model) {
  return addChoiceOption(command, "--field-model", model, parseFieldModelName, fieldModelNames(),
                         "How the map reads the field between its measurements: choose (the "
                         "candidate that predicts each measurement best from the others), or one "
                         "forced: conservative, componentwise, corrected, thin_plate");
}

}  // namespace autograv::cli

#pragma once
// What stands behind a scene's content: the colour that RGBA images are composited on and
// that training, evaluation, Fisher scoring and the final fit render against (one colour
// for both, or the model learns the wrong one), or a fresh random colour per training step
// (3DGS's and splatfacto's choice for alpha data, which keeps the model from painting the
// background into the object) with a fixed colour for everything else.
#include <array>
#include <string>

namespace saresgs {

struct BackgroundChoice {
  bool random = false;                  // a fresh colour per training step
  std::array<float, 3> color{1, 1, 1};  // the colour; with `random`, the one evaluation uses
  bool operator==(const BackgroundChoice&) const = default;
};

// The forms parseBackground takes, for messages and --help.
inline constexpr const char* kBackgroundForms =
    "white, black, random, or R,G,B with three numbers in 0..1 (e.g. 0.5,0.5,0.5)";

// "white", "black", "R,G,B" (three numbers in 0..1) or "random" (evaluated on white).
// Throws InputError(where, "value", ...) naming the accepted forms for anything else;
// `where` is the option or keyword that gave it ("--background").
BackgroundChoice parseBackground(const std::string& text, const std::string& where);

// The inverse of parseBackground for messages and results.json: "white", "black",
// "random", or "R,G,B".
std::string backgroundText(const BackgroundChoice& b);

}  // namespace saresgs

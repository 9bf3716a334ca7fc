// The ARKit shape a rig's own blendshape name denotes. Avatars name their ARKit shapes in many
// ways: ARKit's names in any case ("EyeBlinkLeft"), behind a namespace or prefix
// ("blendShape1.eyeBlinkLeft", "BlendShape.EyeBlinkLeft", "AK_07_EyeBlinkLeft", "Face.jawOpen"),
// with the side as a suffix ("eyeBlink_L", "eyeBlink.R", "mouthSmile_Left", "eyeBlinkL") and
// in snake case ("mouth_smile_l"). This is the one rule every part of the product uses (the C
// ABI's softdeca_blendshape_find_index, hence Unity and Python, and the CLI's avatar folders).
#pragma once

#include <string_view>

namespace softdeca::stream {

// The canonical index (0..51) of the ARKit shape `name` denotes, or -1. The name is split into
// words (at any byte but an ASCII letter or digit, lower-to-upper case changes, letters against
// digits); a trailing side word (L, R, Left, Right in any case) reads as Left/Right; the longest
// run of trailing words that spells a canonical name, case ignored, is the match, so words in
// front of it (a prefix or namespace) are ignored and words after it (a "_corrective" variant)
// mean no match. Names over 256 bytes never match.
int rig_blendshape_index(std::string_view name);

}  // namespace softdeca::stream

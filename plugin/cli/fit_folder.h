// A fit folder, what `softdeca fit MESH --out DIR` writes and `softdeca replay --avatar DIR` reads:
//   DIR/avatar.fit   the fit (softdeca_avatar_fit_save; tied to its bundle)
//   DIR/fit.json     the library's report under "fit" ("poor_fit": kept though it fails the
//                    report's quality bounds), with what the file gave: "source" (the
//                    mesh's path, absolute and from DIR, the names file, the SHA-256 of the mesh
//                    as read), the parts included and left out, each ARKit shape's rig names and
//                    the names not used
//   DIR/fit.png      front and side views of the template on the avatar (fit_picture.h)
// The fit holds no copy of the mesh: the replay reads the mesh again and checks its SHA-256, so a
// changed mesh is refused before the library's own check. `softdeca fit` writes the folder whole
// beside DIR and renames it into place (staged_folder.h): DIR is one fit's folder, never a mix.
#pragma once

#include <string>
#include <vector>

#include "imported_avatar.h"

namespace softdeca::cli {

// The files of a fit folder: what replacing one removes.
std::vector<std::string> fit_folder_files();

bool is_fit_folder(const std::string& dir);
std::string fit_file(const std::string& dir);  // DIR/avatar.fit

// fit.json's text for `avatar` fitted into `dir`, around the library's report (JSON); `poor`: a
// fit that fails the library's quality bounds, kept on request ("poor_fit": true).
std::string fit_json(const AvatarFile& avatar, const std::string& dir, const std::string& library_report, bool poor = false);

// The mesh a fit folder was made for, read again as the fit read it (its names file too);
// throws std::runtime_error when it cannot be found or is not the mesh that was fitted.
AvatarFile read_fitted_mesh(const std::string& dir, const ImportLimits& limits = {});

}  // namespace softdeca::cli

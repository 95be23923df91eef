// The viewer page's template (viewer_page.cpp): HTML, CSS and JavaScript with one
// placeholder, @SCENE@, where viewer.cpp puts the scene as a JSON object:
//   {"width": W, "height": H, "fx": .., "fy": .., "cx": .., "cy": .., "amplitude": ..,
//    "planes": [{"depth": z, "src": "data:image/png;base64,..." or "mpi/layer_00.png"}, ...]}
// with the planes back to front.
#pragma once

namespace ampi {

extern const char kViewerPageTemplate[];

}  // namespace ampi

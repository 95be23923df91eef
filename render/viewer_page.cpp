#include "render/viewer_page.h"

namespace ampi {

const char kViewerPageTemplate[] = R"VIEWER(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>3D photo (ampi)</title>
<style>
  html, body { margin: 0; height: 100%; overflow: hidden; background: #000; }
  #stage img { position: absolute; left: 0; top: 0; transform-origin: 0 0;
               pointer-events: none; user-select: none; -webkit-user-drag: none; }
  #hint { position: fixed; left: 0; right: 0; bottom: 10px; text-align: center;
          font: 13px sans-serif; color: #999; transition: opacity 1s; }
</style>
</head>
<body>
<div id="stage"></div>
<div id="hint">move the mouse, drag a finger or tilt the device</div>
<script>
"use strict";
const scene = @SCENE@;

// 3x3 matrices, row-major arrays of 9 numbers.
function mul(a, b) {
  const m = new Array(9);
  for (let r = 0; r < 3; ++r)
    for (let c = 0; c < 3; ++c)
      m[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
  return m;
}

const K_inverse = [1 / scene.fx, 0, -scene.cx / scene.fx, 0, 1 / scene.fy, -scene.cy / scene.fy, 0, 0, 1];

// H = K_new (I + t n^T / z) K^-1: plane pixels to view pixels, pixel centres at integers.
function planeHomography(depth, pose) {
  const t = pose.t;
  const motion = [1, 0, t[0] / depth, 0, 1, t[1] / depth, 0, 0, 1 + t[2] / depth];
  const K_new = [scene.fx * pose.zoom, 0, scene.cx, 0, scene.fy * pose.zoom, scene.cy, 0, 0, 1];
  return mul(mul(K_new, motion), K_inverse);
}

// CSS puts pixel centres at half-integers; `fit` scales and centres the photo in the window.
function cssTransform(h, fit) {
  const toCss = [1, 0, 0.5, 0, 1, 0.5, 0, 0, 1], fromCss = [1, 0, -0.5, 0, 1, -0.5, 0, 0, 1];
  const m = mul(fit, mul(toCss, mul(h, fromCss)));
  // matrix3d is column-major 4x4; the homography acts on (x, y, w), z passes through.
  return "matrix3d(" + [m[0], m[3], 0, m[6], m[1], m[4], 0, m[7], 0, 0, 1, 0, m[2], m[5], 0, m[8]].join(",") + ")";
}

const stage = document.getElementById("stage");
const layers = scene.planes.map(plane => {
  const img = document.createElement("img");
  img.width = scene.width;
  img.height = scene.height;
  img.alt = "";
  img.src = plane.src;
  stage.appendChild(img);  // back to front: later elements are drawn on top
  return img;
});

function draw(pose) {
  const s = Math.min(window.innerWidth / scene.width, window.innerHeight / scene.height);
  const fit = [s, 0, (window.innerWidth - s * scene.width) / 2, 0, s, (window.innerHeight - s * scene.height) / 2, 0, 0, 1];
  scene.planes.forEach((plane, j) => {
    layers[j].style.transform = cssTransform(planeHomography(plane.depth, pose), fit);
  });
}

// #pose=tx,ty,tz[&zoom=z]: a fixed view, no interaction.
function fixedPose() {
  const params = new URLSearchParams(location.hash.slice(1));
  if (!params.has("pose")) return null;
  const t = params.get("pose").split(",").map(Number);
  const zoom = params.has("zoom") ? Number(params.get("zoom")) : 1;
  if (t.length !== 3 || t.some(v => !isFinite(v)) || !(zoom > 0)) return null;
  return {t: t, zoom: zoom};
}

// The camera follows a point in [-1, 1]^2 (mouse, finger or tilt), eased towards it.
function interact() {
  const nearest = Math.min(...scene.planes.map(p => p.depth));
  const travel = scene.amplitude * nearest;
  const target = {x: 0, y: 0}, current = {x: 0, y: 0};
  const clamp = v => Math.max(-1, Math.min(1, v));
  const aim = (clientX, clientY) => {
    target.x = clamp(2 * clientX / window.innerWidth - 1);
    target.y = clamp(2 * clientY / window.innerHeight - 1);
  };
  window.addEventListener("mousemove", e => aim(e.clientX, e.clientY));
  window.addEventListener("touchmove", e => {
    aim(e.touches[0].clientX, e.touches[0].clientY);
    e.preventDefault();
  }, {passive: false});
  window.addEventListener("deviceorientation", e => {
    if (e.gamma === null || e.beta === null) return;
    target.x = clamp(e.gamma / 30);
    target.y = clamp((e.beta - 45) / 30);  // a phone held at about 45 degrees is centred
  });
  let drawn = null;  // the pointer position last drawn; null: draw again
  window.addEventListener("resize", () => { drawn = null; });
  setTimeout(() => { document.getElementById("hint").style.opacity = 0; }, 4000);
  function frame() {
    current.x += 0.12 * (target.x - current.x);
    current.y += 0.12 * (target.y - current.y);
    if (!drawn || Math.abs(drawn.x - current.x) + Math.abs(drawn.y - current.y) > 1e-4) {
      // The camera moves towards the pointer: t = -centre.
      draw({t: [-current.x * travel, -current.y * travel, 0], zoom: 1});
      drawn = {x: current.x, y: current.y};
    }
    requestAnimationFrame(frame);
  }
  requestAnimationFrame(frame);
}

const fixed = fixedPose();
if (fixed) {
  document.getElementById("hint").remove();
  draw(fixed);
  window.addEventListener("resize", () => draw(fixed));
} else {
  interact();
}
</script>
</body>
</html>
)VIEWER";

}  // namespace ampi

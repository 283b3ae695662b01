// The page of `grammarc view`: a 3D Tiles tileset streamed by 3d-tiles-renderer into a three.js scene, a
// camera to orbit (drag), pan (right drag), zoom (wheel) and fly (W A S D, Q E), and a click that shows the
// lot and symbol under the cursor from the tiles' EXT_structural_metadata.
//
// The page keeps its counters in `window.viewer` and in the status line, for a person and for the
// headless test alike: tiles loaded, tiles visible, frames per second, and when loading settled.
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { TilesRenderer } from "3d-tiles-renderer";
import { GLTFExtensionsPlugin, ReorientationPlugin } from "3d-tiles-renderer/plugins";
import { InstanceFeatures, pickedFeatures } from "./features.js";

const params = new URLSearchParams(location.search);
const viewer = { tilesLoaded: 0, tilesVisible: 0, fps: 0, frames: 0, settledAt: null, error: null };
window.viewer = viewer;

const canvas = document.getElementById("view");
const status = document.getElementById("status");
const info = document.getElementById("info");
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xdfe6ee);
scene.add(new THREE.HemisphereLight(0xffffff, 0x8d8170, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 2.2);
sun.position.set(0.5, 1.0, 0.3);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(55, 1, 0.5, 200000);
const controls = new OrbitControls(camera, canvas);
controls.screenSpacePanning = false;
controls.maxPolarAngle = Math.PI * 0.495;

const tiles = new TilesRenderer(params.get("tileset") ?? "tiles/tileset.json");
tiles.registerPlugin(new GLTFExtensionsPlugin({ metadata: true, plugins: [(parser) => new InstanceFeatures(parser)] }));
tiles.registerPlugin(new ReorientationPlugin({ up: "+z", recenter: true }));
tiles.setCamera(camera);
scene.add(tiles.group);
tiles.addEventListener("load-model", ({ scene: model }) => {
  viewer.tilesLoaded += 1;
  // Lambert shading: the tiles' materials are flat colours (and colour maps), which a physically based
  // material draws no better at several times the cost per pixel
  model.traverse((object) => {
    if (!object.isMesh || !object.material.isMeshStandardMaterial) return;
    const { color, map, vertexColors, transparent, opacity, side, flatShading } = object.material;
    object.material.dispose();
    object.material = new THREE.MeshLambertMaterial({ color, map, vertexColors, transparent, opacity, side, flatShading });
  });
});
tiles.addEventListener("dispose-model", () => { viewer.tilesLoaded -= 1; });
tiles.addEventListener("load-error", (event) => { viewer.error = String(event.error); });
tiles.addEventListener("load-root-tileset", () => {
  // the whole city in view, from the south-east and above
  const sphere = new THREE.Sphere();
  tiles.getBoundingSphere(sphere);
  tiles.group.updateMatrixWorld(true);
  sphere.applyMatrix4(tiles.group.matrixWorld);
  controls.target.copy(sphere.center);
  const distance = sphere.radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2));
  camera.position.copy(sphere.center).add(new THREE.Vector3(0.45, 0.55, 0.7).normalize().multiplyScalar(distance));
  camera.far = sphere.radius * 20;
  camera.updateProjectionMatrix();
  controls.update();
});

function resize() {
  const width = canvas.clientWidth, height = canvas.clientHeight;
  renderer.setSize(width, height, false);
  camera.aspect = width / height;
  camera.updateProjectionMatrix();
  tiles.setResolutionFromRenderer(camera, renderer);
}
window.addEventListener("resize", resize);
resize();

// flying: keys move the camera and its target together, faster the farther the target
const held = new Set();
window.addEventListener("keydown", (event) => held.add(event.code));
window.addEventListener("keyup", (event) => held.delete(event.code));
const moves = { KeyW: [0, 0, -1], KeyS: [0, 0, 1], KeyA: [-1, 0, 0], KeyD: [1, 0, 0], KeyQ: [0, -1, 0], KeyE: [0, 1, 0],
                ArrowUp: [0, 0, -1], ArrowDown: [0, 0, 1], ArrowLeft: [-1, 0, 0], ArrowRight: [1, 0, 0] };
function fly(seconds) {
  const step = new THREE.Vector3();
  for (const code of held) if (moves[code]) step.add(new THREE.Vector3(...moves[code]));
  if (step.lengthSq() === 0) return;
  const speed = Math.max(camera.position.distanceTo(controls.target), 20) * seconds;
  const forward = new THREE.Vector3().subVectors(controls.target, camera.position).setY(0).normalize();
  const right = new THREE.Vector3().crossVectors(forward, camera.up).normalize();
  const move = right.multiplyScalar(step.x).add(forward.multiplyScalar(-step.z)).add(new THREE.Vector3(0, step.y, 0));
  move.multiplyScalar(speed);
  camera.position.add(move);
  controls.target.add(move);
}

// picking: a click (not a drag) shows the features under the cursor
const down = new THREE.Vector2();
canvas.addEventListener("pointerdown", (event) => down.set(event.clientX, event.clientY));
canvas.addEventListener("pointerup", (event) => {
  if (down.distanceTo(new THREE.Vector2(event.clientX, event.clientY)) > 4) return;
  showPicked(pickAt(event.clientX, event.clientY));
});

// the features of the nearest surface at a point of the page, or null
function pickAt(x, y) {
  const rect = canvas.getBoundingClientRect();
  const pointer = new THREE.Vector2(((x - rect.left) / rect.width) * 2 - 1, -((y - rect.top) / rect.height) * 2 + 1);
  const raycaster = new THREE.Raycaster();
  raycaster.setFromCamera(pointer, camera);
  const hit = raycaster.intersectObject(tiles.group, true)[0];
  return hit ? pickedFeatures(hit) : null;
}
viewer.pickAt = pickAt;

function showPicked(picked) {
  info.replaceChildren();
  if (!picked) { info.hidden = true; return; }
  info.hidden = false;
  for (const [title, values] of Object.entries(picked)) {
    const heading = document.createElement("h2");
    heading.textContent = title;
    const table = document.createElement("table");
    for (const [key, value] of Object.entries(values)) {
      const row = table.insertRow();
      row.insertCell().textContent = key;
      row.insertCell().textContent = typeof value === "number" && !Number.isInteger(value) ? value.toPrecision(6) : String(value);
    }
    info.append(heading, table);
  }
}

const clock = new THREE.Clock();
let second = performance.now(), framesThisSecond = 0, lastBusy = performance.now();
renderer.setAnimationLoop(() => {
  fly(Math.min(clock.getDelta(), 0.1));
  controls.update();
  camera.updateMatrixWorld();
  tiles.update();
  renderer.render(scene, camera);
  viewer.frames += 1;
  viewer.triangles = renderer.info.render.triangles;
  framesThisSecond += 1;
  const now = performance.now();
  if (now - second >= 1000) {
    viewer.fps = (framesThisSecond * 1000) / (now - second);
    second = now;
    framesThisSecond = 0;
  }
  const { queued, downloading, parsing, visible } = tiles.stats;
  viewer.tilesVisible = visible;
  // settled: a second without a tile queued, downloading or parsing; the time is when the last one ended
  if (queued + downloading + parsing > 0 || viewer.tilesLoaded === 0) lastBusy = now;
  else if (viewer.settledAt === null && now - lastBusy > 1000) viewer.settledAt = lastBusy;
  status.textContent = `${viewer.tilesLoaded} tiles loaded, ${visible} visible · ${viewer.fps.toFixed(0)} fps` +
    (downloading + parsing ? ` · loading ${downloading + parsing}` : "") + (viewer.error ? ` · error: ${viewer.error}` : "");
});

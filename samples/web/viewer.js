// SPDX-License-Identifier: MIT
// aggrelod web viewer: streams a 3D Tiles tileset written by `aggrelod bake ... --tiles` with
// three.js and 3DTilesRendererJS, choosing tiles by screen-space error (docs/design.md §3).
//
// Query parameters (all optional):
//   tileset=URL        tileset.json to open (default ./tileset/tileset.json, as serve.mjs serves it)
//   camera=x,y,z       camera position in the scene's own glTF coordinates (y-up, scene units);
//                      default: looking at the scene from 2.5 radii away
//   target=x,y,z       point looked at (default: centre of the root tile's bounding volume)
//   errorTarget=px     screen-space error in pixels above which a tile is refined (default 16)
//   fov=degrees        vertical field of view (default 60)
//
// The tileset is z-up (3D Tiles); the viewer turns it by -90 degrees about x so that the scene
// appears in its original y-up coordinates, the ones `camera` and `target` are given in.
//
// Once loading has settled (nothing queued, downloading or parsing, and the same visible
// tiles for 10 frames), window.viewerState.settled is true and window.viewerState.visibleTiles
// (also the JSON text of #visible-tiles) lists the drawn tiles:
// {node, uri, geometricError, leaf, level}, sorted by node.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TilesRenderer } from '3d-tiles-renderer/three';

const state = { settled: false, error: null, visibleTiles: [], frames: 0, camera: null, target: null };
window.viewerState = state;
const info = document.getElementById('info');

function fail(message) {
  state.error = message;
  info.textContent = 'error: ' + message;
  console.error(message);
}

const params = new URLSearchParams(window.location.search);

/** Parses "x,y,z" into a Vector3, or null when the parameter is absent. */
function vectorParameter(name) {
  const text = params.get(name);
  if (text === null) return null;
  const values = text.split(',').map(Number);
  if (values.length !== 3 || values.some((v) => !Number.isFinite(v))) {
    throw new Error(`query parameter ${name}=${text}: expected three numbers x,y,z`);
  }
  return new THREE.Vector3(values[0], values[1], values[2]);
}

function numberParameter(name, fallback) {
  const text = params.get(name);
  if (text === null) return fallback;
  const value = Number(text);
  if (!Number.isFinite(value) || value <= 0) {
    throw new Error(`query parameter ${name}=${text}: expected a positive number`);
  }
  return value;
}

let tilesetUrl, cameraPosition, targetPosition, errorTarget, fov;
try {
  tilesetUrl = params.get('tileset') || './tileset/tileset.json';
  cameraPosition = vectorParameter('camera');
  targetPosition = vectorParameter('target');
  errorTarget = numberParameter('errorTarget', 16);
  fov = numberParameter('fov', 60);
} catch (e) {
  fail(e.message);
  throw e;
}

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.setClearColor(0xdfe3e8);
document.body.appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.0);
sun.position.set(0.5, 1.0, 0.3);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(fov, window.innerWidth / window.innerHeight, 0.01, 1000);
const controls = new OrbitControls(camera, renderer.domElement);

const tiles = new TilesRenderer(tilesetUrl);
tiles.errorTarget = errorTarget;
tiles.group.rotation.x = -Math.PI / 2; // 3D Tiles z-up -> the scene's glTF y-up
scene.add(tiles.group);
tiles.setCamera(camera);
tiles.setResolutionFromRenderer(camera, renderer);

tiles.addEventListener('load-error', (event) => {
  fail(`cannot load ${event.url || 'a tile'}: ${event.error && event.error.message ? event.error.message : event.error}`);
});

let framed = false;
/** Places the camera once the root tile's bounding volume is known. */
function frameScene() {
  const sphere = new THREE.Sphere();
  if (!tiles.getBoundingSphere(sphere)) return false;
  tiles.group.updateMatrixWorld(true);
  sphere.applyMatrix4(tiles.group.matrixWorld);
  const target = targetPosition || sphere.center.clone();
  const position = cameraPosition ||
    target.clone().add(new THREE.Vector3(1.0, 0.8, 1.2).normalize().multiplyScalar(2.5 * sphere.radius));
  camera.position.copy(position);
  controls.target.copy(target);
  const distance = position.distanceTo(sphere.center) + sphere.radius;
  camera.near = Math.max(distance * 1e-4, 1e-6);
  camera.far = distance * 4;
  camera.updateProjectionMatrix();
  controls.update();
  state.camera = position.toArray();
  state.target = target.toArray();
  return true;
}

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
  tiles.setResolutionFromRenderer(camera, renderer);
});

function describeTile(tile) {
  const extras = tile.extras || {};
  return {
    node: typeof extras.node === 'number' ? extras.node : null,
    uri: tile.content && tile.content.uri ? tile.content.uri : null,
    geometricError: tile.geometricError,
    leaf: !tile.children || tile.children.length === 0,
    level: typeof extras.level === 'number' ? extras.level : null,
  };
}

let lastKey = '';
let publishedKey = '';
let stableFrames = 0;
let loadEnded = false;
tiles.addEventListener('tiles-load-end', () => { loadEnded = true; });
tiles.addEventListener('tiles-load-start', () => { loadEnded = false; state.settled = false; });

function watchVisibleTiles() {
  const visible = [...tiles.visibleTiles].map(describeTile).sort((a, b) => (a.node ?? -1) - (b.node ?? -1));
  const key = JSON.stringify(visible);
  const { queued, downloading, parsing } = tiles.stats;
  const idle = loadEnded && queued + downloading + parsing === 0;
  stableFrames = idle && key === lastKey && visible.length > 0 ? stableFrames + 1 : 0;
  lastKey = key;
  if (stableFrames >= 10 && (!state.settled || key !== publishedKey)) {
    state.visibleTiles = visible;
    state.settled = true;
    publishedKey = key;
    document.getElementById('visible-tiles').textContent = key;
  } else if (stableFrames === 0 && key !== publishedKey) {
    state.settled = false; // the camera moved: a new set of tiles is on its way
  }
  const leaves = visible.filter((t) => t.leaf).length;
  if (!state.error) {
    info.textContent = `${visible.length} tiles drawn (${leaves} original objects, ${visible.length - leaves} proxies)` +
      `\nnodes: ${visible.map((t) => t.node).join(' ')}` + (state.settled ? '' : '\nloading...');
  }
}

function animate() {
  requestAnimationFrame(animate);
  if (!framed) framed = frameScene();
  controls.update();
  camera.updateMatrixWorld();
  tiles.update();
  renderer.render(scene, camera);
  state.frames++;
  if (framed) watchVisibleTiles();
}
animate();

// SPDX-License-Identifier: MIT
// A plain glTF import with three.js: GLTFLoader loads each file and only gltf.scene (the
// default scene, what engines add by default) is put in the view. Nothing of aggrelod is used,
// so this shows what a glTF importer that knows neither MSFT_lod nor the physics extensions
// makes of the bake's files.
//
// Query parameters:
//   files=URL,URL,...  GLB files to load (default ./tileset/proxies.glb)
//   show=K             index in `files` of the file drawn in the view (default 0)
//
// When every file is loaded, window.importState = {done: true, files: [summary per file]}, with
// per file: url, scenes (count), defaultScene (index), extensionsUsed, fileMeshes and
// fileTriangles (every mesh of the file, from its JSON), and for the objects of gltf.scene:
// visibleMeshes, visibleTriangles, meshesWithoutNormals, meshesWithoutColors, names (of the
// visible meshes) and sourceIds (extras.source_ids of each visible mesh, in order).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const state = { done: false, error: null, files: [] };
window.importState = state;
const info = document.getElementById('info');
const params = new URLSearchParams(window.location.search);
const files = (params.get('files') || './tileset/proxies.glb').split(',').filter((f) => f.length > 0);
const show = Number(params.get('show') || 0);

function trianglesOf(geometry) {
  return geometry.index ? geometry.index.count / 3 : geometry.attributes.position.count / 3;
}

/** What the file holds in all, from its JSON: meshes and triangles of every primitive. */
function fileTotals(json) {
  let triangles = 0;
  for (const mesh of json.meshes || [])
    for (const p of mesh.primitives) {
      const accessor = p.indices !== undefined ? json.accessors[p.indices] : json.accessors[p.attributes.POSITION];
      triangles += p.indices !== undefined ? accessor.count / 3 : accessor.count / 3;
    }
  return { fileMeshes: (json.meshes || []).length, fileTriangles: triangles };
}

function summarise(url, gltf) {
  const json = gltf.parser.json;
  const s = {
    url, scenes: gltf.scenes.length, defaultScene: json.scene ?? 0, extensionsUsed: json.extensionsUsed || [],
    ...fileTotals(json), visibleMeshes: 0, visibleTriangles: 0, meshesWithoutNormals: 0, meshesWithoutColors: 0,
    names: [], sourceIds: [],
  };
  gltf.scene.updateMatrixWorld(true);
  gltf.scene.traverseVisible((o) => {
    if (!o.isMesh) return;
    s.visibleMeshes += 1;
    s.visibleTriangles += trianglesOf(o.geometry);
    if (!o.geometry.attributes.normal) s.meshesWithoutNormals += 1;
    if (!o.geometry.attributes.color) s.meshesWithoutColors += 1;
    // A single-primitive mesh node is the Mesh itself; its node's extras are its userData.
    const holder = o.userData && o.userData.source_ids ? o : o.parent;
    s.names.push(holder.name || o.name);
    s.sourceIds.push(holder.userData.source_ids || null);
  });
  return s;
}

async function main() {
  const renderer = new THREE.WebGLRenderer({ antialias: true });
  renderer.setSize(window.innerWidth, window.innerHeight);
  document.body.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xdfe3e8);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.set(1, 3, 2);
  scene.add(sun);
  const loader = new GLTFLoader();
  for (const url of files) {
    const gltf = await loader.loadAsync(url);
    state.files.push(summarise(url, gltf));
    if (state.files.length - 1 === show) scene.add(gltf.scene);
  }
  // Camera on the shown file's box, from the front-right and above (z-up samples: +z is up).
  const box = new THREE.Box3().setFromObject(scene);
  const centre = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-6);
  const camera = new THREE.PerspectiveCamera(40, window.innerWidth / window.innerHeight, radius / 100, radius * 100);
  camera.up.set(0, 0, 1);
  camera.position.copy(centre).add(new THREE.Vector3(1.2, -1.6, 1.1).normalize().multiplyScalar(2.6 * radius));
  camera.lookAt(centre);
  renderer.render(scene, camera);
  const shown = state.files[show];
  info.textContent = shown ? `${shown.url}: ${shown.visibleMeshes} meshes, ${shown.visibleTriangles} triangles drawn ` +
    `(the file holds ${shown.fileMeshes} meshes, ${shown.fileTriangles} triangles)` : 'nothing shown';
  state.done = true;
}

main().catch((e) => {
  state.error = String(e && e.stack ? e.stack : e);
  info.textContent = 'error: ' + state.error;
});

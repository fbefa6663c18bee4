"use strict";
// Image-pair viewer of Prism's HTML reports (report/mod.rs writes the markup).
(function () {
  // sRGB encoding of linear [0, 1] through a table (the exact curve per pixel is slow on
  // 4K images; 16384 steps keep every output code reachable).
  const LUT_SIZE = 16384;
  const srgbLut = new Uint8ClampedArray(LUT_SIZE + 1);
  for (let i = 0; i <= LUT_SIZE; i++) {
    const v = i / LUT_SIZE;
    const e = v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
    srgbLut[i] = Math.round(255 * e);
  }

  function rgbaOf(img) {
    const c = document.createElement("canvas");
    c.width = img.naturalWidth;
    c.height = img.naturalHeight;
    const g = c.getContext("2d", { willReadFrequently: true });
    g.drawImage(img, 0, 0);
    return g.getImageData(0, 0, c.width, c.height).data;
  }

  // One embedded image: display bytes as they are, or RGBE decoded as Radiance's
  // colr_color does: (mantissa + 0.5) · 2^(exponent − 136), 0 when the exponent is 0.
  async function load(source) {
    const imgs = Array.from(source.querySelectorAll("img"));
    // After the load event every image is complete; drawImage decodes synchronously.
    await Promise.all(imgs.filter((i) => !i.complete).map((i) => i.decode()));
    const w = Number(source.dataset.width), h = Number(source.dataset.height);
    for (const i of imgs) {
      if (i.naturalWidth !== w || i.naturalHeight !== h) throw new Error("image size mismatch");
    }
    if (source.dataset.kind === "display") return { kind: "display", w, h, rgba: rgbaOf(imgs[0]), count: 1 };
    const m = rgbaOf(imgs[0]), e = rgbaOf(imgs[1]);
    const linear = new Float32Array(w * h * 3);
    for (let p = 0; p < w * h; p++) {
      const x = e[4 * p];
      if (x === 0) continue;
      const f = Math.pow(2, x - 136);
      for (let c = 0; c < 3; c++) linear[3 * p + c] = (m[4 * p + c] + 0.5) * f;
    }
    return { kind: "radiance", w, h, linear, count: 2 };
  }

  function paint(canvas, image, ev) {
    canvas.width = image.w;
    canvas.height = image.h;
    const g = canvas.getContext("2d");
    const out = g.createImageData(image.w, image.h);
    const d = out.data;
    if (image.kind === "display") {
      d.set(image.rgba);
    } else {
      const scale = Math.pow(2, ev) * LUT_SIZE, lin = image.linear;
      for (let p = 0, n = image.w * image.h; p < n; p++) {
        for (let c = 0; c < 3; c++) {
          const v = lin[3 * p + c] * scale;
          d[4 * p + c] = v >= LUT_SIZE ? 255 : srgbLut[v | 0];
        }
        d[4 * p + 3] = 255;
      }
    }
    g.putImageData(out, 0, 0);
  }

  async function setUp(viewer) {
    const a = await load(viewer.querySelector('.source[data-role="a"]'));
    const b = await load(viewer.querySelector('.source[data-role="b"]'));
    const layerA = viewer.querySelector(".layer-a"), layerB = viewer.querySelector(".layer-b");
    const split = viewer.querySelector(".split"), zoom = viewer.querySelector(".zoom");
    const exposure = viewer.querySelector(".exposure"), ev = viewer.querySelector(".ev");
    const toggle = viewer.querySelector(".toggle"), divider = viewer.querySelector(".divider");
    const state = viewer.querySelector(".state");
    let shown = "split";
    // Small images start magnified (nearest-neighbour) to about 480 px wide.
    if (zoom.value === "1" && a.w < 320) {
      zoom.value = String(Math.min(8, Math.pow(2, Math.floor(Math.log2(480 / a.w)))));
    }
    const repaint = () => {
      const stops = exposure ? Number(exposure.value) : 0;
      if (ev) ev.textContent = (stops >= 0 ? "+" : "") + stops.toFixed(1) + " EV";
      paint(layerA, a, stops);
      paint(layerB, b, stops);
    };
    const layout = () => {
      const z = zoom.value;
      const width = z === "fit" ? Math.min(a.w, viewer.clientWidth - 4) : a.w * Number(z);
      for (const c of [layerA, layerB]) c.style.width = width + "px";
      const s = shown === "a" ? 100 : shown === "b" ? 0 : Number(split.value);
      layerA.style.clipPath = "inset(0 " + (100 - s) + "% 0 0)";
      divider.style.left = s + "%";
      divider.style.display = shown === "split" ? "block" : "none";
      state.textContent = shown === "split" ? "A | B split at " + s + " %" : "showing " + shown.toUpperCase();
      toggle.textContent = shown === "b" ? "show A" : "show B";
    };
    toggle.addEventListener("click", () => { shown = shown === "b" ? "a" : "b"; layout(); });
    split.addEventListener("input", () => { shown = "split"; layout(); });
    zoom.addEventListener("change", layout);
    if (exposure) exposure.addEventListener("input", repaint);
    viewer.addEventListener("flip", () => { shown = shown === "b" ? "a" : "b"; layout(); });
    window.addEventListener("resize", layout);
    repaint();
    layout();
    return a.count + b.count;
  }

  document.addEventListener("keydown", (event) => {
    if (event.key !== "f" && event.key !== "F") return;
    for (const v of document.querySelectorAll(".viewer")) v.dispatchEvent(new Event("flip"));
  });

  async function main() {
    let decoded = 0;
    const maps = Array.from(document.querySelectorAll("img.map"));
    await Promise.all(maps.filter((i) => !i.complete).map((i) => i.decode()));
    decoded += maps.length;
    for (const viewer of document.querySelectorAll(".viewer")) decoded += await setUp(viewer);
    document.body.dataset.decodedImages = String(decoded);
    document.body.dataset.ready = "true";
  }
  // Started on the load event (every embedded image loaded), which headless browsers
  // wait for, so that a DOM dump sees the finished page.
  const start = () =>
    main().catch((error) => {
      document.body.dataset.ready = "error";
      document.body.dataset.error = String(error);
    });
  if (document.readyState === "complete") start();
  else window.addEventListener("load", start);
})();

// SPDX-License-Identifier: BSD-3-Clause
// The benchmark's peer in the browser: vtk.js (npm @kitware/vtk.js) extracting an isosurface
// with vtkImageMarchingCubes (JavaScript, one thread) and drawing it with its WebGL renderer,
// the way Kitware's Glance and vtk.js examples do. Bundled by esbuild for the benchmark
// (Python/benchmark_web.py); window.vtkBench is driven like window.mediso.
import "@kitware/vtk.js/Rendering/Profiles/Geometry";
import vtkGenericRenderWindow from "@kitware/vtk.js/Rendering/Misc/GenericRenderWindow";
import vtkImageData from "@kitware/vtk.js/Common/DataModel/ImageData";
import vtkDataArray from "@kitware/vtk.js/Common/Core/DataArray";
import vtkImageMarchingCubes from "@kitware/vtk.js/Filters/General/ImageMarchingCubes";
import vtkMapper from "@kitware/vtk.js/Rendering/Core/Mapper";
import vtkActor from "@kitware/vtk.js/Rendering/Core/Actor";

const ARRAYS = { int8: Int8Array, uint8: Uint8Array, int16: Int16Array, uint16: Uint16Array,
  int32: Int32Array, uint32: Uint32Array, float32: Float32Array, float64: Float64Array };

function finish(gl) {
  const pixel = new Uint8Array(4);
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel); // waits for the frame
}

window.vtkBench = {
  async load({ url, dims, spacing, origin, type, size }) {
    const container = document.getElementById("view");
    container.style.width = size[0] + "px";
    container.style.height = size[1] + "px";
    const start = performance.now();
    const buffer = await (await fetch(url)).arrayBuffer();
    const values = new ARRAYS[type](buffer);
    const image = vtkImageData.newInstance({ spacing, origin });
    image.setDimensions(dims);
    image.getPointData().setScalars(vtkDataArray.newInstance({ values, numberOfComponents: 1, name: "v" }));
    this.window = vtkGenericRenderWindow.newInstance({ background: [0.1, 0.12, 0.16] });
    this.window.setContainer(container);
    this.window.resize();
    this.marching = vtkImageMarchingCubes.newInstance({ contourValue: 0, computeNormals: true,
      mergePoints: true });
    this.marching.setInputData(image);
    const mapper = vtkMapper.newInstance();
    mapper.setInputConnection(this.marching.getOutputPort());
    const actor = vtkActor.newInstance();
    actor.setMapper(mapper);
    actor.getProperty().set({ ambient: 0.15, diffuse: 0.8, specular: 0.25, specularPower: 30 });
    actor.getProperty().setColor(0.93, 0.85, 0.75);
    this.renderer = this.window.getRenderer();
    this.renderer.addActor(actor);
    this.gl = this.window.getApiSpecificRenderWindow().get3DContext();
    return { loadMs: performance.now() - start };
  },
  // One isovalue change and its frame, timed to the frame's completion.
  change(value, resetCamera = false) {
    const start = performance.now();
    this.marching.setContourValue(value);
    this.marching.update();
    const extracted = performance.now();
    if (resetCamera) {
      this.renderer.resetCamera(); // VTK's default view, as the page's
    }
    this.window.getRenderWindow().render();
    finish(this.gl);
    const end = performance.now();
    return { ms: end - start, extractMs: extracted - start,
      triangles: this.marching.getOutputData().getNumberOfPolys() };
  },
  // A frame of the same surface with nothing changed: the drawing alone.
  redraw() {
    const start = performance.now();
    this.window.getRenderWindow().render();
    finish(this.gl);
    return performance.now() - start;
  },
};

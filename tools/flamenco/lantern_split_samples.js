// SPDX-License-Identifier: GPL-3.0-or-later
// Flamenco 3 job type: one Lantern still split by samples across workers (docs/farm.md).
// Each chunk task renders the whole frame with its own seed and its share of the samples
// (`blender -b file.blend -E LANTERN --python-expr <seed, samples> -f N`); the merge task, once
// every chunk is in, runs `lantern.merge` in a worker's Blender (the extension carries the
// `lantern` package) and writes the sample-weighted mean, which refuses mismatched chunks.
// Install: copy this file into the `scripts/` folder beside flamenco-manager and restart it.

const JOB_TYPE = {
    label: "Lantern Split-Sample Still",
    description: "Render one frame with Lantern on several workers, each a share of the " +
        "samples with its own seed, then merge the EXRs weighted by their samples.",
    settings: [
        { key: "frame", type: "int32", required: true, eval: "C.scene.frame_current",
          description: "Frame to render" },
        { key: "samples", type: "int32", required: true, eval: "C.scene.lantern.samples",
          propargs: { min: 1 }, description: "Samples per pixel of the merged image" },
        { key: "chunks", type: "int32", required: true, default: 4, propargs: { min: 1, max: 1024 },
          description: "Sample chunks: one task, one worker each" },
        { key: "seed", type: "int32", required: true, eval: "C.scene.lantern.seed",
          visible: "submission", description: "Seed of chunk 0; chunk k renders with seed + k" },
        { key: "render_output_root", type: "string", subtype: "dir_path", required: true,
          visible: "submission", description: "Directory the chunks and the merged frame go to" },
        { key: "render_output_path", type: "string", subtype: "file_path", editable: false,
          eval: "str(Path(abspath(settings.render_output_root), jobname, '{timestamp}'))",
          description: "Directory of this job's chunks and merged frame" },
        { key: "multilayer", type: "bool", required: false,
          eval: "C.scene.render.image_settings.file_format == 'OPEN_EXR_MULTILAYER'",
          visible: "hidden", description: "Keep Blender's passes (multilayer EXR)" },
        { key: "blendfile", type: "string", required: true, visible: "web",
          description: "Path of the Blend file to render" },
        { key: "scene", type: "string", required: true, eval: "C.scene.name", visible: "web",
          description: "Name of the scene to render" },
    ],
};

function compileJob(job) {
    const settings = job.settings;
    if (settings.chunks < 1 || settings.samples < settings.chunks) {
        throw `Need 1 <= chunks <= samples, got ${settings.chunks} chunks for ` +
            `${settings.samples} samples`;
    }
    const outDir = outputDir(job);
    settings.render_output_path = outDir;
    const chunkFiles = [];
    const renderTasks = [];
    for (let k = 0; k < settings.chunks; k++) {
        const task = authorChunkTask(settings, outDir, k);
        chunkFiles.push(path.join(outDir, "chunks", `chunk_${k}_` + frameName(settings.frame)));
        renderTasks.push(task);
        job.addTask(task);
    }
    const merge = authorMergeTask(settings, chunkFiles,
                                  path.join(outDir, frameName(settings.frame)));
    for (const t of renderTasks) {
        merge.addDependency(t);
    }
    job.addTask(merge);
}

// The samples of chunk k: an even share, the remainder to the first chunks (the merge weighs
// each chunk by the samples it records, so uneven shares are fine).
function chunkSamples(samples, chunks, k) {
    return Math.floor(samples / chunks) + (k < samples % chunks ? 1 : 0);
}

function frameName(frame) {
    return String(frame).padStart(6, "0") + ".exr";
}

function outputDir(job) {
    const dir = job.settings.render_output_path;
    if (!dir) {
        throw "no render_output_path setting!";
    }
    return dir.replace(/{([^}]+)}/g, (match, name) =>
        name === "timestamp" ? formatTimestampLocal(job.created) : match);
}

function pyString(s) {
    return JSON.stringify(String(s));  // a JSON string is a valid Python string literal
}

function authorChunkTask(settings, outDir, k) {
    const task = author.Task(`render-chunk-${k}`, "blender");
    const format = settings.multilayer ? "OPEN_EXR_MULTILAYER" : "OPEN_EXR";
    const expr = [
        "import bpy",
        "s = bpy.context.scene",
        `s.lantern.seed = ${settings.seed + k}`,
        `s.lantern.samples = ${chunkSamples(settings.samples, settings.chunks, k)}`,
        `s.render.image_settings.file_format = ${pyString(format)}`,
        "s.render.image_settings.color_depth = '32'",
        "s.render.image_settings.exr_codec = 'ZIP'",  // lossless, and read without OpenImageIO
        "s.render.use_file_extension = True",
    ].join("; ");
    task.addCommand(author.Command("blender-render", {
        exe: "{blender}",
        exeArgs: "{blenderArgs}",
        argsBefore: [],
        blendfile: settings.blendfile,
        args: [
            "--scene", settings.scene,
            "--engine", "LANTERN",
            "--python-expr", expr,
            "--render-output", path.join(outDir, "chunks", `chunk_${k}_######`),
            "--render-frame", String(settings.frame),
        ],
    }, 1));
    return task;
}

function authorMergeTask(settings, chunkFiles, output) {
    const task = author.Task("merge-chunks", "blender");
    const expr = "from lantern.merge import merge_files; " +
        `merge_files([${chunkFiles.map(pyString).join(", ")}], ${pyString(output)})`;
    task.addCommand(author.Command("blender-render", {
        exe: "{blender}",
        exeArgs: "{blenderArgs}",
        argsBefore: ["--python-exit-code", "1"],  // a refused merge fails the task
        blendfile: settings.blendfile,
        args: ["--python-expr", expr],
    }, 1));
    return task;
}

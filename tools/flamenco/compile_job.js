// Runs a Flamenco 3 job compiler script outside Flamenco Manager, for tests and for a look at
// the tasks a job becomes: `node compile_job.js <script.js> <settings.json>` prints the tasks
// (name, type, commands with their parameters, dependencies) as JSON. It provides the globals
// a job script sees in the Manager: author.Task / author.Command, path, print,
// formatTimestampLocal.
const fs = require("fs");
const nodePath = require("path").posix;
const vm = require("vm");

const [script, settingsFile] = process.argv.slice(2);
const tasks = [];
const author = {
    Task(name, type) {
        const task = { name, type, commands: [], dependencies: [] };
        task.addCommand = (cmd) => task.commands.push(cmd);
        task.addDependency = (dep) => task.dependencies.push(dep.name);
        return task;
    },
    Command(name, parameters, totalFrames) {
        return { name, parameters, totalFrames };
    },
};
const job = {
    settings: JSON.parse(fs.readFileSync(settingsFile, "utf8")),
    created: new Date(0),
    addTask: (t) => tasks.push(t),
};
const sandbox = {
    author, job,
    path: { join: nodePath.join, dirname: nodePath.dirname, basename: nodePath.basename },
    print: (...args) => console.error(...args.map(String)),
    formatTimestampLocal: (d) => d.toISOString().replace(/[-:]/g, "").slice(0, 15),
};
vm.createContext(sandbox);
vm.runInContext(fs.readFileSync(script, "utf8") + "\ncompileJob(job);", sandbox);
const clean = tasks.map(({ name, type, commands, dependencies }) =>
    ({ name, type, commands, dependencies }));
process.stdout.write(JSON.stringify(clean, null, 1) + "\n");

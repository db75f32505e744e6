// Validates each glTF file named on the command line with the Khronos glTF validator (the npm
// package pinned in package.json). Prints one JSON line per file (uri, errors, warnings, infos,
// the messages); exits 1 if any file has an error or a warning, 2 on a file it cannot read.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

let failed = false;
for (const file of process.argv.slice(2)) {
    let bytes;
    try {
        bytes = await readFile(file);
    } catch (e) {
        console.error(`${file}: cannot read: ${e.message}`);
        process.exit(2);
    }
    const report = await validator.validateBytes(new Uint8Array(bytes), {
        uri: path.basename(file),
        maxIssues: 50,
        externalResourceFunction: (uri) => readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))),
    });
    const { numErrors, numWarnings, numInfos, messages } = report.issues;
    console.log(JSON.stringify({ uri: file, errors: numErrors, warnings: numWarnings, infos: numInfos,
                                 messages: messages.map((m) => `${m.code} ${m.pointer ?? ''}: ${m.message}`),
                                 info: report.info }));
    if (numErrors > 0 || numWarnings > 0) failed = true;
}
process.exit(failed ? 1 : 0);

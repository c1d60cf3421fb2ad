// Reads an MCAP file with the official reader (@mcap/core, pinned in
// package-lock.json) twice: indexed (footer, summary, chunk and message
// indexes, as Foxglove opens a file) and streamed record by record with CRC
// validation (the chunks' and the data section's). Writes one line per message
// of the indexed read, `log_time<TAB>topic<TAB>data`, to OUT_LINES, and prints a
// JSON summary of both reads on stdout. Exit 1 on any error the reader raises.
//
//   node read_mcap.mjs FILE.mcap OUT_LINES
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { open, readFile, writeFile } from "node:fs/promises";

const [file, outLines] = process.argv.slice(2);
if (!file || !outLines) {
  console.error("usage: node read_mcap.mjs FILE.mcap OUT_LINES");
  process.exit(2);
}

const decoder = new TextDecoder("utf-8", { fatal: true });
const handle = await open(file, "r");
const readable = {
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, size) => {
    const buffer = new Uint8Array(Number(size));
    const { bytesRead } = await handle.read(buffer, 0, Number(size), Number(offset));
    if (bytesRead !== Number(size)) throw new Error(`short read at ${offset}`);
    return buffer;
  },
};

const indexed = await McapIndexedReader.Initialize({ readable });
const lines = [];
const byTopic = {};
let lastTime = -1n;
let outOfOrder = 0;
for await (const message of indexed.readMessages({ validateCrcs: true })) {
  const channel = indexed.channelsById.get(message.channelId);
  const schema = indexed.schemasById.get(channel.schemaId);
  if (schema === undefined || schema.encoding !== "jsonschema") throw new Error(`channel ${channel.topic} has no JSON schema`);
  const text = decoder.decode(message.data);
  JSON.parse(text); // the message encoding says json: it must parse
  if (message.logTime < lastTime) outOfOrder += 1;
  lastTime = message.logTime;
  byTopic[channel.topic] = (byTopic[channel.topic] ?? 0) + 1;
  lines.push(`${message.logTime}\t${channel.topic}\t${text}`);
}
const metadata = {};
for await (const record of indexed.readMetadata()) metadata[record.name] = Object.fromEntries(record.metadata);
await handle.close();
await writeFile(outLines, lines.join("\n") + (lines.length > 0 ? "\n" : ""));

const stream = new McapStreamReader({ validateCrcs: true });
stream.append(await readFile(file));
const streamed = { messages: 0, chunks: 0, dataEnd: false, footer: false };
for (let record; (record = stream.nextRecord()); ) {
  if (record.type === "Message") streamed.messages += 1;
  if (record.type === "DataEnd") streamed.dataEnd = true;
  if (record.type === "Footer") streamed.footer = true;
}
streamed.done = stream.done();

console.log(JSON.stringify({
  indexed: {
    messages: lines.length,
    byTopic,
    outOfOrder,
    chunks: indexed.chunkIndexes.length,
    statisticsMessageCount: Number(indexed.statistics?.messageCount ?? -1n),
    summaryOffsets: indexed.summaryOffsetsByOpcode.size,
    library: indexed.header.library,
  },
  streamed,
  metadata,
}));

// Shapes of the graph format (README "The graph format") and of the node schemas (`vitrine nodes --json`).

export type Json = null | boolean | number | string | Json[] | JsonObject;
export interface JsonObject {
  [key: string]: Json;
}

export type PortKind = 'texture' | 'scene' | 'camera' | 'buffer';

export interface InputSchema {
  name: string;
  kind: PortKind;
  doc?: string;
  optional?: boolean;
}

export interface OutputSchema {
  name: string;
  kind: PortKind;
  doc?: string;
  format?: string;
}

export type ParamType = 'int' | 'float' | 'bool' | 'enum' | 'string' | 'path' | 'vec2' | 'vec3' | 'vec4';

export interface ParamSchema {
  name: string;
  type: ParamType;
  default: Json;
  doc?: string;
  min?: number;
  max?: number;
  choices?: string[];
}

export interface NodeSchema {
  type: string;
  doc?: string;
  pass?: string;
  inputs: InputSchema[];
  outputs: OutputSchema[];
  params: ParamSchema[];
}

export type SchemaMap = Map<string, NodeSchema>;

export interface Position {
  x: number;
  y: number;
}

/** A parsed "node.port" or "node.port@prev" reference. */
export interface PortRef {
  node: string;
  port: string;
  prev: boolean;
}

export function isObject(v: Json | undefined): v is JsonObject {
  return typeof v === 'object' && v !== null && !Array.isArray(v);
}

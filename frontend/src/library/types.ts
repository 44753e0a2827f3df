// Shapes of the library, agreement, adjudication and dashboard API: aliases of the types
// generated from the server's OpenAPI schema (see ../api/types.ts).
import type { components } from "../api/schema";

type Schemas = components["schemas"];

export type LibrarySegment = Schemas["Segment"] & { distance?: number };
export type Span = Schemas["Span"];
export type Pair = Schemas["Pair"];
export type Agreement = Schemas["Agreement"];
export type Gold = Schemas["GoldBody"];
export type Adjudication = Schemas["Adjudication"];
export type CaptureState = Schemas["CaptureStateEnum"];
export type Dashboard = Schemas["Dashboard"];

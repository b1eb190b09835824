// The studio page: mount the editor on the document, talking to the server over HTTP.
import { mount } from "./studio.js";

mount(document);

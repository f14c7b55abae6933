// The keywords `sprig schema` writes for editors beside standard JSON Schema (model/schema.cpp):
// errorMessage and patternErrorMessage, the messages yaml-language-server and VS Code show
// instead of their generic ones ("Incorrect type. Expected array"). Declared to ajv as a
// vocabulary of annotations, so that its strict mode knows them and checks everything else:
//   ajv compile -s schema.json --spec=draft7 -c ./scripts/ajv/editor-keywords.js
module.exports = (ajv) => ajv.addVocabulary(["errorMessage", "patternErrorMessage"]);
